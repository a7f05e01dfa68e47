//! The ten CGAL meshes: fetched once (shared by concurrent test processes), they load, validate,
//! and normalise to the stated size; a corrupted cache file is caught by its checksum.

use taction::mesh::{BuildOptions, EdgeTopology, MeshError, ObjectSet, ObjectSource};
use taction::mesh::{CGAL_MESHES, DEB_FILE, ObjectCache, ensure_fetched};

#[test]
fn fetched_meshes_load_validate_and_normalise() {
    let cache = ensure_fetched().unwrap();
    cache.verify().unwrap();
    for m in &CGAL_MESHES {
        let loaded = cache.load(m).unwrap_or_else(|e| panic!("{}: {e}", m.name));
        assert!(loaded.mesh.triangles.len() >= 1000, "{}", m.name);
        // The dragon scan has two small open holes; every other mesh is closed and clean.
        let w = loaded.warnings;
        if m.name == "dragon" {
            let counts = (
                w.boundary_edges,
                w.boundary_loops,
                w.non_manifold_edges,
                w.zero_area_faces,
            );
            assert_eq!(counts, (6, 2, 0, 0), "dragon: {w}");
        } else {
            assert!(w.is_clean(), "{}: {w}", m.name);
        }
    }
    let set = ObjectSet::shapes();
    assert_eq!(set.objects.len(), 12);
    let options = BuildOptions { cache, fetch: false };
    for object in set.build(&options).unwrap() {
        let (lo, hi) = object.mesh.bounds().unwrap();
        assert!(
            (object.mesh.bounding_diagonal_m().unwrap() - 0.12).abs() < 1e-12,
            "{}",
            object.name
        );
        assert!(lo.z.abs() < 1e-15, "{} does not rest on z = 0", object.name);
        assert!(
            (lo.x + hi.x).abs() < 1e-12 && (lo.y + hi.y).abs() < 1e-12,
            "{} is not centred",
            object.name
        );
        if EdgeTopology::new(&object.mesh).is_consistently_oriented() {
            assert!(object.mesh.signed_volume() > 0.0, "{} faces inward", object.name);
        }
    }
}

#[test]
fn corrupted_cache_file_is_detected_by_checksum_and_repaired_from_the_cached_deb() {
    let shared = ensure_fetched().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let cache = ObjectCache::new(dir.path());
    assert!(matches!(cache.verify(), Err(MeshError::NotFetched { .. })));
    let missing = cache.load(&CGAL_MESHES[0]).unwrap_err();
    assert!(missing.to_string().contains("taction objects fetch"), "{missing}");

    std::fs::create_dir_all(cache.mesh_dir()).unwrap();
    for m in &CGAL_MESHES {
        std::fs::copy(shared.mesh_path(m), cache.mesh_path(m)).unwrap();
    }
    std::fs::copy(shared.deb_path(), cache.deb_path()).unwrap();
    cache.verify().unwrap();

    let victim = &CGAL_MESHES[3];
    let path = cache.mesh_path(victim);
    let mut bytes = std::fs::read(&path).unwrap();
    let k = bytes.len() / 2;
    bytes[k] = if bytes[k] == b'1' { b'2' } else { b'1' };
    std::fs::write(&path, &bytes).unwrap();
    assert!(matches!(cache.verify(), Err(MeshError::Checksum { .. })));
    let e = cache.load(victim).unwrap_err();
    assert!(
        matches!(e, MeshError::Checksum { .. }) && e.to_string().contains(victim.file),
        "{e}"
    );

    // Re-extracting from the cached package (no download) repairs the cache.
    cache.ensure_fetched().unwrap();
    cache.verify().unwrap();
    assert!(cache.deb_path().ends_with(DEB_FILE));
}

#[test]
fn building_without_the_cache_says_how_to_fetch() {
    let dir = tempfile::tempdir().unwrap();
    let options = BuildOptions {
        cache: ObjectCache::new(dir.path().join("empty")),
        fetch: false,
    };
    let set = ObjectSet::shapes();
    let e = set.build_object("bunny", &options).unwrap_err();
    assert!(
        matches!(e, MeshError::NotFetched { .. }) && e.to_string().contains("objects fetch"),
        "{e}"
    );
    // The chess pieces need no cache.
    assert!(set.build_object("pawn", &options).is_ok());
    assert!(
        matches!(&set.objects[0].source, ObjectSource::Cgal { file, .. } if file == "ChineseDragon-10kv.off")
    );
}
