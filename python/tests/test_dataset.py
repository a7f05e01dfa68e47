"""Datasets from Python: the collected arrays, determinism, and the round trips through the CLI's
file, pandas, npz and Parquet."""

import numpy as np
import pytest

import taction


def test_collected_arrays_have_the_documented_shapes(small_dataset):
    n = len(small_dataset)
    assert n >= 80  # 40 converged readings of each piece, plus the attempts that did not converge
    assert small_dataset.images.shape == (n, 6, 6)
    assert small_dataset.images.dtype == np.float32
    assert small_dataset.pad_pose.shape == (n, 9)
    assert set(small_dataset.object) == {"pawn", "rook"}
    converged = small_dataset.status == "converged"
    assert converged.sum() == 80
    assert np.all(small_dataset.cause[converged] == "")
    assert small_dataset.images[converged].max() <= 1.0
    assert small_dataset.images[converged].max(axis=(1, 2)).min() > 0.0
    # The normal and up of every pose are unit vectors.
    poses = small_dataset.pad_pose[converged]
    assert np.allclose(np.linalg.norm(poses[:, 3:6], axis=1), 1.0)
    assert np.allclose(np.linalg.norm(poses[:, 6:9], axis=1), 1.0)
    assert small_dataset.header["sensor"]["rows"] == 6
    assert len(small_dataset.converged()) == 80


def test_same_seed_same_dataset(chess):
    a = taction.collect(chess[:1], readings=5, seed=11)
    b = taction.collect(chess[:1], readings=5, seed=11)
    c = taction.collect(chess[:1], readings=5, seed=12)
    assert np.array_equal(a.images, b.images)
    assert np.array_equal(a.pad_pose, b.pad_pose)
    assert not np.array_equal(a.pad_pose[: len(c)], c.pad_pose[: len(a)])


def test_the_csv_reads_back_and_pandas_reads_it_with_comment(small_dataset, tmp_path):
    import pandas as pd

    path = tmp_path / "data.csv"
    small_dataset.save(path)
    again = taction.Dataset.load(path)
    assert np.array_equal(again.images, small_dataset.images)
    assert np.array_equal(again.pad_pose, small_dataset.pad_pose, equal_nan=True)
    frame = pd.read_csv(path, comment="#")
    assert len(frame) == len(small_dataset)
    assert list(frame["object"]) == list(small_dataset.object)
    taxels = frame[[f"t_{r}_{c}" for r in range(6) for c in range(6)]].to_numpy()
    assert np.array_equal(taxels.reshape(-1, 6, 6).astype(np.float32), again.images)
    assert np.allclose(frame["pad_x_m"], small_dataset.pad_pose[:, 0], equal_nan=True)


def test_npz_round_trip(small_dataset, tmp_path):
    path = tmp_path / "data.npz"
    small_dataset.export(path, format="npz")
    with np.load(path) as npz:  # no pickles: plain numeric and unicode arrays
        assert np.array_equal(npz["images"], small_dataset.images)
        assert np.array_equal(npz["pad_pose"], small_dataset.pad_pose, equal_nan=True)
        assert list(npz["object"]) == list(small_dataset.object)
        assert list(npz["status"]) == list(small_dataset.status)
        assert list(npz["cause"]) == list(small_dataset.cause)


def test_parquet_round_trip(small_dataset, tmp_path):
    pd = pytest.importorskip("pandas")
    pytest.importorskip("pyarrow")
    path = tmp_path / "data.parquet"
    small_dataset.export(path, format="parquet")
    frame = pd.read_parquet(path)
    assert len(frame) == len(small_dataset)
    assert list(frame["object"]) == list(small_dataset.object)
    assert list(frame["status"]) == list(small_dataset.status)
    frame_pandas = small_dataset.to_pandas()
    assert list(frame_pandas["object"]) == list(small_dataset.object)


def test_a_corrupt_dataset_file_names_the_file(tmp_path):
    path = tmp_path / "cut.csv"
    path.write_text("# taction dataset\n# {not json\n")
    with pytest.raises(taction.TactionError, match="cut.csv"):
        taction.Dataset.load(path)


def test_a_set_name_collects_its_objects_and_counts_are_whole_numbers(chess):
    by_name = taction.collect("chess", readings=3, seed=2)
    by_list = taction.collect(taction.objects("chess"), readings=3, seed=2)
    assert list(by_name.objects) == list(by_list.objects)
    assert np.array_equal(by_name.images, by_list.images)
    for bad in [dict(readings=-5), dict(seed=-1), dict(threads=-1), dict(readings=2.5)]:
        with pytest.raises(taction.TactionError, match="whole number"):
            taction.collect(chess, **bad)
    with pytest.raises(taction.TactionError, match="neither a list"):
        taction.collect(42)


def test_a_free_object_is_the_planners_recorded_and_its_material_checked(chess):
    pawn = [o for o in chess if o.name == "pawn"]
    data = taction.collect(pawn, mode="planner", readings=2, seed=4, free_object=True, object_friction=0.5)
    assert data.header["free_object"] == {"density_kg_m3": 1000.0, "friction": 0.5}
    fixed = taction.collect(pawn, mode="planner", readings=2, seed=4)
    assert "free_object" not in fixed.header
    with pytest.raises(taction.TactionError, match="object_density: only with free_object"):
        taction.collect(pawn, mode="planner", readings=2, object_density=800.0)
    with pytest.raises(taction.TactionError, match="object_density 5: object density 5 kg/m3 is outside"):
        taction.collect(pawn, mode="planner", readings=2, free_object=True, object_density=5.0)
    with pytest.raises(taction.TactionError, match="free_object"):
        taction.collect(pawn, mode="sampler", readings=2, free_object=True)
    # Every touch records where a free object lay after it; a fixed object's columns are empty.
    assert data.to_pandas()["object_after_x_m"].notna().all()
    assert fixed.to_pandas()["object_after_x_m"].isna().all()


def test_a_push_perturbs_a_free_object_and_only_a_free_one(chess):
    pawn = [o for o in chess if o.name == "pawn"]
    pushed = taction.collect(
        pawn, mode="planner", readings=2, seed=4, free_object=True, perturb_deg=10.0, perturb_frac=0.1, perturb_by="push"
    )
    assert pushed.header["perturbation"]["pushed"] is True
    with pytest.raises(taction.TactionError, match="push"):
        taction.collect(pawn, mode="planner", readings=2, perturb_deg=10.0, perturb_by="push")
    with pytest.raises(taction.TactionError, match="perturb_by: 'shove' is not one of teleport, push"):
        taction.collect(pawn, mode="planner", readings=2, perturb_by="shove")


def test_an_argument_of_the_other_mode_is_refused(chess):
    with pytest.raises(taction.TactionError, match="local_probability"):
        taction.collect(chess, mode="sampler", readings=2, local_probability=0.9)
    with pytest.raises(taction.TactionError, match="reachable_by_arm"):
        taction.collect(chess, mode="planner", readings=2, reachable_by_arm=True)
    with pytest.raises(taction.TactionError, match="from_above"):
        taction.collect(chess, mode="planner", readings=2, from_above=True)
    with pytest.raises(taction.TactionError, match="whole number"):
        taction.collect(chess, readings=True)
