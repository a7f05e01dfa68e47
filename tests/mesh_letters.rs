//! Raised letters of the built-in letters set (OpenDyslexic, capital 'I' of DejaVu Sans Mono): every
//! letter is a closed, consistently oriented solid with the glyph's holes, the right heights and
//! volume, and no letter is another one turned round.

use std::collections::BTreeMap;

use std::path::Path;

use taction::mesh::Font;
use taction::mesh::{EdgeTopology, MeshError, ObjectSet, TriMesh, ValidationReport, connected_components};
use taction::mesh::{LetterPair, letter_pairs};
use taction::mesh::{LetterStyle, alphabet, letter_from_name, letter_name, letter_outline, raised_letter};

/// The font the built-in set draws `ch` in.
fn built_in_font(ch: char) -> Font {
    if ch == 'I' {
        Font::load_capital_i().unwrap()
    } else {
        Font::load_default().unwrap()
    }
}

/// Counters of the built-in letters (single-storey 'g').
fn expected_holes(ch: char) -> usize {
    match ch {
        'B' => 2,
        'A' | 'D' | 'O' | 'P' | 'Q' | 'R' | 'a' | 'b' | 'd' | 'e' | 'g' | 'o' | 'p' | 'q' => 1,
        _ => 0,
    }
}

/// The triangles lying in the plane z = `z` as their own mesh.
fn faces_at(mesh: &TriMesh, z: f64) -> TriMesh {
    TriMesh {
        vertices: mesh.vertices.clone(),
        triangles: mesh
            .triangles
            .iter()
            .copied()
            .filter(|t| t.iter().all(|&i| mesh.vertices[i as usize].z == z))
            .collect(),
    }
}

/// Checks that `ch` of `font` is a closed, consistently oriented solid with `holes` counters in its
/// raised face (and ink in one piece, two for 'i' and 'j'), the right heights and volume.
fn closed_letter_with_holes(font: &Font, ch: char, holes: usize) -> TriMesh {
    let style = LetterStyle::default();
    let z_top = style.plate_thickness_m + style.raise_m;
    let font_name = font.path().display();
    let mesh = raised_letter(font, ch, &style).unwrap_or_else(|e| panic!("{font_name} {ch}: {e}"));
    let report = ValidationReport::of(&mesh);
    assert!(report.is_clean(), "{font_name} {ch}: {report}");
    let topology = EdgeTopology::new(&mesh);
    assert_eq!(
        topology.boundary_edges().count(),
        0,
        "{font_name} {ch}: open boundary edges"
    );
    assert!(
        topology.is_closed() && topology.is_consistently_oriented(),
        "{font_name} {ch}"
    );
    // A plate with the letter on top, counters sunk to the plate: one shell of genus 0.
    assert_eq!(
        topology.euler_characteristic(&mesh),
        2,
        "{font_name} {ch} is not one sphere-like shell"
    );
    assert_eq!(connected_components(&mesh), 1, "{font_name} {ch}");

    let (lo, hi) = mesh.bounds().unwrap();
    assert_eq!(
        (lo.z, hi.z),
        (0.0, z_top),
        "{font_name} {ch}: plate bottom and raised top"
    );
    assert!(
        (lo.x + hi.x).abs() < 1e-12 && (lo.y + hi.y).abs() < 1e-12,
        "{font_name} {ch} is not centred"
    );

    // The raised face is a planar region: its Euler characteristic is pieces - counters.
    let top = faces_at(&mesh, z_top);
    let top_topology = EdgeTopology::new(&top);
    let components = connected_components(&top) as i64;
    let counters = components - top_topology.euler_characteristic(&top);
    assert_eq!(
        counters, holes as i64,
        "{font_name} {ch}: holes in the raised face"
    );
    assert_eq!(
        components,
        if matches!(ch, 'i' | 'j') { 2 } else { 1 },
        "{font_name} {ch}: pieces"
    );

    // Volume = plate area * plate thickness + glyph area * raise height, exactly.
    let plate_area = (hi.x - lo.x) * (hi.y - lo.y);
    let expected = plate_area * style.plate_thickness_m + top.total_area() * style.raise_m;
    assert!(
        (mesh.signed_volume() - expected).abs() < 1e-9 * expected,
        "{font_name} {ch}: volume"
    );
    assert!(
        (faces_at(&mesh, style.plate_thickness_m).total_area() + top.total_area() - plate_area).abs() < 1e-12,
        "{font_name} {ch}: plate and raised face do not tile the plate"
    );
    mesh
}

#[test]
fn all_52_letters_are_closed_oriented_solids_with_their_holes() {
    let mut meshes = BTreeMap::new();
    for ch in alphabet() {
        meshes.insert(
            ch,
            closed_letter_with_holes(&built_in_font(ch), ch, expected_holes(ch)),
        );
    }
    let letters: Vec<char> = meshes.keys().copied().collect();
    for (i, a) in letters.iter().enumerate() {
        for b in &letters[i + 1..] {
            assert_ne!(meshes[a], meshes[b], "{a} and {b} are the same mesh");
        }
    }
}

/// Counters of the DejaVu letters (Sans, Sans Mono and Serif agree: single-storey 'g').
fn dejavu_holes(ch: char) -> usize {
    match ch {
        'B' => 2,
        'A' | 'D' | 'O' | 'P' | 'Q' | 'R' | 'a' | 'b' | 'd' | 'e' | 'g' | 'o' | 'p' | 'q' => 1,
        _ => 0,
    }
}

/// DejaVu Serif's 'B' and 'D' were open: their counters' bottom edges continue the top edge of
/// the serif, and the triangulation of the raised face spanned both with one edge.
#[test]
fn every_letter_of_the_dejavu_fonts_is_a_closed_solid_with_its_counters() {
    let mut fonts = vec![Font::load(Path::new("taction:DejaVuSansMono.ttf")).unwrap()];
    for file in ["DejaVuSerif.ttf", "DejaVuSans.ttf"] {
        let path = Path::new("/usr/share/fonts/truetype/dejavu").join(file);
        match Font::load(&path) {
            Ok(font) => fonts.push(font),
            Err(e) => eprintln!("skipping {file}: not installed here (fonts-dejavu-core): {e}"),
        }
    }
    for font in &fonts {
        for ch in alphabet() {
            closed_letter_with_holes(font, ch, dejavu_holes(ch));
        }
    }
}

#[test]
fn capitals_are_about_25_mm_and_letters_repeat_bit_for_bit() {
    let font = Font::load_default().unwrap();
    let style = LetterStyle::default();
    let h = raised_letter(&font, 'H', &style).unwrap();
    let top = faces_at(&h, style.plate_thickness_m + style.raise_m);
    let (lo, hi) = top.bounds().unwrap();
    let ys: Vec<f64> = top
        .triangles
        .iter()
        .flatten()
        .map(|&i| top.vertices[i as usize].y)
        .collect();
    let height = ys.iter().cloned().fold(f64::MIN, f64::max) - ys.iter().cloned().fold(f64::MAX, f64::min);
    assert!((height - 0.025).abs() < 1e-9, "H is {height} m tall");
    assert!(hi.x - lo.x > 0.01);
    assert_eq!(raised_letter(&font, 'H', &style).unwrap(), h);

    let taller = LetterStyle {
        raise_m: 0.005,
        ..style
    };
    let t = raised_letter(&font, 'H', &taller).unwrap();
    assert_eq!(t.bounds().unwrap().1.z, 0.007);
    assert!(t.signed_volume() > h.signed_volume());
}

#[test]
fn bad_fonts_styles_and_glyphs_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let not_a_font = dir.path().join("notes.ttf");
    std::fs::write(&not_a_font, b"not a font").unwrap();
    let e = Font::load(&not_a_font).unwrap_err();
    assert!(
        matches!(e, MeshError::Font { .. }) && e.to_string().contains("notes.ttf"),
        "{e}"
    );
    let missing = Font::load(&dir.path().join("missing.ttf")).unwrap_err();
    assert!(missing.to_string().contains("missing.ttf"));

    let font = Font::load_default().unwrap();
    let bad = LetterStyle {
        raise_m: 0.0,
        ..LetterStyle::default()
    };
    assert!(matches!(
        raised_letter(&font, 'A', &bad),
        Err(MeshError::InvalidParameter { field: "raise_m", .. })
    ));
    // A character the font draws nothing for.
    assert!(matches!(
        raised_letter(&font, ' ', &LetterStyle::default()),
        Err(MeshError::Glyph { .. })
    ));
}

#[test]
fn letter_names_round_trip() {
    let names: Vec<String> = alphabet().map(letter_name).collect();
    assert_eq!(names.len(), 52);
    assert_eq!((names[0].as_str(), names[51].as_str()), ("upper_A", "lower_z"));
    for (ch, name) in alphabet().zip(&names) {
        assert_eq!(letter_from_name(name), Some(ch));
    }
    assert_eq!(letter_from_name("upper_a"), None);
    assert_eq!(letter_from_name("lower_ab"), None);
    assert_eq!(letter_from_name("pawn"), None);
}

/// Largest best-rotation IoU allowed between two built-in letters (`meshes/README.md` has the table).
/// Touch cannot tell which way a letter lies (the descriptors are rotation invariant, Sec. IV), so
/// two letters this alike or more would be told apart by little more than chance.
const MOST_ALIKE_IOU: f64 = 0.75;

#[test]
fn no_built_in_letter_is_another_turned_round_and_dejavu_sans_shows_why_that_matters() {
    let pairs = letter_pairs(&ObjectSet::default_letters(LetterStyle::default()).unwrap()).unwrap();
    assert_eq!(pairs.len(), 52 * 51 / 2);
    let most = &pairs[0];
    assert!(
        most.iou < MOST_ALIKE_IOU,
        "{} and {} overlap {:.3} at their best turn",
        most.first,
        most.second,
        most.iou
    );
    // Known answers: in DejaVu Sans 'q' is a 'b' turned half round, 'u' an 'n', and 'I' and 'l' are
    // both plain bars; the built-in capital 'I' has cross-bars.
    let dejavu = Font::load(Path::new("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf")).unwrap();
    let dejavu_pairs = letter_pairs(&ObjectSet::letters(&dejavu, LetterStyle::default())).unwrap();
    let iou = |pairs: &[LetterPair], a: &str, b: &str| {
        pairs
            .iter()
            .find(|p| (p.first == a && p.second == b) || (p.first == b && p.second == a))
            .map(|p| p.iou)
            .unwrap()
    };
    for (a, b) in [
        ("lower_b", "lower_q"),
        ("lower_d", "lower_p"),
        ("lower_n", "lower_u"),
        ("upper_I", "lower_l"),
    ] {
        assert!(iou(&dejavu_pairs, a, b) > 0.95, "DejaVu Sans {a}/{b}");
        assert!(iou(&pairs, a, b) < 0.7, "built-in {a}/{b}");
    }
    let capital_i = letter_outline(&Font::load_capital_i().unwrap(), 'I', &LetterStyle::default()).unwrap();
    let xs = || capital_i.contours.iter().flatten().map(|p| p.x);
    let width_m = xs().fold(f64::MIN, f64::max) - xs().fold(f64::MAX, f64::min);
    assert!(width_m > 0.01, "capital I is {width_m} m wide: no cross-bars");
}
