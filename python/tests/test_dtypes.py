"""One dtype per column wherever a dataset goes: Parquet, npz, pandas (`Dataset.to_pandas`) and the
`Dataset`'s own arrays. Taxels float32, every pose column float64 (also the object's pose of an
object that never moved, whose CSV numbers are whole), `iterations` and `contact` int64, names
strings."""

import numpy as np
import pytest

import taction

pd = pytest.importorskip("pandas")
pytest.importorskip("pyarrow")

ROWS = COLS = 6
TAXELS = [f"t_{r}_{c}" for r in range(ROWS) for c in range(COLS)]
OBJECT_POSE = ["object_x_m", "object_y_m", "object_z_m", "object_qw", "object_qx", "object_qy", "object_qz"]
PAD_POSE = ["pad_x_m", "pad_y_m", "pad_z_m", "pad_normal_x", "pad_normal_y", "pad_normal_z",
            "pad_up_x", "pad_up_y", "pad_up_z"]
NAMES = ["object", "status", "strategy", "cause", "touched_bodies"]


@pytest.fixture(scope="module")
def perturbed(chess):
    return taction.collect(chess, mode="planner", readings=3, seed=3, perturb_deg=5.0, perturb_frac=0.05)


@pytest.fixture(params=["fixed", "perturbed"])
def dataset(request, small_dataset, perturbed):
    return small_dataset if request.param == "fixed" else perturbed


def test_the_datasets_cover_both_cases(small_dataset, perturbed):
    fixed = small_dataset.to_pandas()[OBJECT_POSE].to_numpy()
    moved = perturbed.to_pandas()[OBJECT_POSE].to_numpy()
    # A fixed object's pose is whole numbers (0 0 0, 1 0 0 0: read as int64 before); a perturbed
    # one's moves between readings.
    assert np.all(fixed == np.round(fixed)) and len(np.unique(fixed, axis=0)) == 1
    assert len(np.unique(moved, axis=0)) > 1
    assert (perturbed.status != "converged").any()  # attempts without a reading: empty causes too


def expect_frame_dtypes(frame, where):
    assert list(frame.columns[:4]) == ["object", "status", "strategy", "iterations"], where
    for column in TAXELS:
        assert frame[column].dtype == np.float32, (where, column, frame[column].dtype)
    for column in OBJECT_POSE + PAD_POSE:
        assert frame[column].dtype == np.float64, (where, column, frame[column].dtype)
    assert frame["iterations"].dtype == np.int64, where
    # Every simulated reading is a press of its own: -1, not a missing value.
    assert frame["contact"].dtype == np.int64 and (frame["contact"] == -1).all(), where
    for column in NAMES:
        assert pd.api.types.is_string_dtype(frame[column]), (where, column, frame[column].dtype)
        assert not frame[column].isna().any(), (where, column)  # no reading's name is missing


def test_pandas_and_parquet_give_each_column_one_dtype(dataset, tmp_path):
    frame = dataset.to_pandas()
    path = tmp_path / "data.parquet"
    dataset.export(path, format="parquet")
    parquet = pd.read_parquet(path)
    expect_frame_dtypes(frame, "to_pandas")
    expect_frame_dtypes(parquet, "parquet")
    assert list(frame.columns) == list(parquet.columns)
    assert dict(frame.dtypes) == dict(parquet.dtypes)
    # The same values, too: the file's numbers read back exactly.
    images = frame[TAXELS].to_numpy().reshape(-1, ROWS, COLS)
    assert np.array_equal(images, dataset.images)
    assert np.array_equal(parquet[TAXELS].to_numpy().reshape(-1, ROWS, COLS), dataset.images)
    assert np.array_equal(frame[PAD_POSE].to_numpy(), dataset.pad_pose, equal_nan=True)
    assert np.array_equal(frame[OBJECT_POSE].to_numpy(), parquet[OBJECT_POSE].to_numpy())
    for column in NAMES:
        assert list(frame[column]) == list(parquet[column]) == list(getattr(dataset, column)), column

    import pyarrow.parquet as pq

    schema = pq.read_schema(path)
    for column in TAXELS:
        assert str(schema.field(column).type) == "float", column
    for column in OBJECT_POSE + PAD_POSE:
        assert str(schema.field(column).type) == "double", column
    assert str(schema.field("iterations").type) == "int64"
    assert str(schema.field("contact").type) == "int64"


def test_npz_and_the_datasets_arrays_give_each_column_one_dtype(dataset, tmp_path):
    path = tmp_path / "data.npz"
    dataset.export(path, format="npz")
    with np.load(path) as npz:
        assert npz["images"].dtype == np.float32
        assert npz["pad_pose"].dtype == np.float64
        assert npz["object_pose"].dtype == np.float64
        assert npz["iterations"].dtype == np.int64
        assert npz["contact"].dtype == np.int64
        assert np.array_equal(npz["contact"], dataset.contact)
        for column in NAMES:
            assert npz[column].dtype.kind == "U", column
        assert np.array_equal(npz["images"], dataset.images)
        assert np.array_equal(npz["object_pose"], dataset.to_pandas()[OBJECT_POSE].to_numpy())
    assert dataset.images.dtype == np.float32
    assert dataset.pad_pose.dtype == np.float64
    assert dataset.iterations.dtype == np.int64
    assert dataset.contact.dtype == np.int64 and (dataset.contact == -1).all()
    for column in NAMES:
        assert getattr(dataset, column).dtype.kind == "U", column
