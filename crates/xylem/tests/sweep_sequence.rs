//! Assembling a sweep folder: frames written in slices (as `--frames-range` farming does) become
//! one contact sheet, animated PNG, CSV and viewer; missing or mismatched frames are named.

use glam::Vec3;
use std::path::PathBuf;
use xylem::picture::png::read_png_rgb8;
use xylem::sweep::sequence::{
    assemble, write_frame, AssembleOptions, FrameRecord, Region, SequenceError, ANIMATION,
    CONTACT_SHEET, CSV, VIEWER,
};
use xylem::sweep::LightArc;

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("xylem-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 16×8 frame whose left half brightens with the light angle and whose right half dims.
fn frame(angle_deg: f32) -> Vec<Vec3> {
    let t = (angle_deg + 60.0) / 120.0;
    (0..16 * 8)
        .map(|i| Vec3::splat(if i % 16 < 8 { t } else { 1.0 - t }))
        .collect()
}

fn regions() -> Vec<Region> {
    let r = |name: &str, x0, x1| Region {
        name: name.into(),
        x0,
        y0: 0,
        x1,
        y1: 8,
    };
    vec![r("left", 0, 8), r("right", 8, 16)]
}

fn render_slice(dir: &std::path::Path, arc: &LightArc, range: std::ops::Range<usize>) {
    for i in range {
        let deg = arc.angle_deg(i);
        let px = frame(deg);
        let rec = FrameRecord::measure(i, arc.frames, deg, (16, 8), &px, &regions());
        write_frame(dir, &rec, &px, 0.0).unwrap();
    }
}

#[test]
fn slices_rendered_apart_assemble_into_one_sequence() {
    let arc = LightArc::new(-60.0, 60.0, 7).unwrap();
    let (a, b) = (temp_dir("slice-a"), temp_dir("slice-b"));
    render_slice(&a, &arc, 0..4);
    render_slice(&b, &arc, 4..7);
    // Assembling one slice alone names what is missing and how to render it.
    let e = assemble(&a, &AssembleOptions::default()).unwrap_err();
    assert!(matches!(e, SequenceError::Missing { .. }), "{e}");
    assert!(e.to_string().contains("4..=6") && e.to_string().contains("--frames-range 4..7"));
    // Gather the farmed frames in one folder, as the cluster notes do with rsync.
    for entry in std::fs::read_dir(&b).unwrap() {
        let p = entry.unwrap().path();
        std::fs::copy(&p, a.join(p.file_name().unwrap())).unwrap();
    }
    let done = assemble(&a, &AssembleOptions::default()).unwrap();
    assert_eq!(done.frames, 7);

    let sheet = read_png_rgb8(&a.join(CONTACT_SHEET)).unwrap();
    // 7 frames → 4 columns, 2 rows of 16×8 thumbnails with 4-pixel gaps.
    assert_eq!((sheet.width, sheet.height), (4 * 16 + 5 * 4, 2 * 8 + 3 * 4));

    let dec = png::Decoder::new(std::fs::File::open(a.join(ANIMATION)).unwrap());
    let reader = dec.read_info().unwrap();
    let actl = reader.info().animation_control.expect("an animated PNG");
    assert_eq!((actl.num_frames, actl.num_plays), (7, 0));

    let csv = std::fs::read_to_string(a.join(CSV)).unwrap();
    let rows: Vec<Vec<f32>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 7);
    for (i, r) in rows.iter().enumerate() {
        let t = (arc.angle_deg(i) + 60.0) / 120.0;
        assert_eq!(r[0] as usize, i);
        assert!((r[1] - arc.angle_deg(i)).abs() < 1e-4);
        // Luminance of grey t is t; the whole-image mean of t and 1−t is 0.5.
        assert!((r[2] - 0.5).abs() < 1e-5);
        assert!((r[6] - t).abs() < 1e-5 && (r[7] - (1.0 - t)).abs() < 1e-5);
    }
    let html = std::fs::read_to_string(a.join(VIEWER)).unwrap();
    assert!(html.contains("frame_0006.png") && html.contains("type=\"range\""));
    for d in [a, b] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

#[test]
fn records_from_different_sweeps_are_refused() {
    let d = temp_dir("mixed");
    render_slice(&d, &LightArc::new(-60.0, 60.0, 3).unwrap(), 0..3);
    let px = frame(0.0);
    let stray = FrameRecord::measure(3, 5, 0.0, (16, 8), &px, &[]);
    write_frame(&d, &stray, &px, 0.0).unwrap();
    let e = assemble(&d, &AssembleOptions::default()).unwrap_err();
    assert!(matches!(e, SequenceError::Mismatch { .. }), "{e}");
    assert!(e.to_string().contains("frame_0003.json"), "{e}");
    std::fs::remove_dir_all(&d).unwrap();
    let empty = temp_dir("empty");
    assert!(matches!(
        assemble(&empty, &AssembleOptions::default()),
        Err(SequenceError::Empty { .. })
    ));
    std::fs::remove_dir_all(&empty).unwrap();
}

/// The streamed assembly (contact sheet band by band, animation a few frames at a time) gives
/// the pixels of the whole-image layout: every thumbnail blitted into one sheet at
/// (gap + column·(w + gap), gap + row·(h + gap)) with its label, and every frame in the APNG.
#[test]
fn the_streamed_sheet_and_animation_hold_every_frame_where_the_layout_puts_it() {
    use xylem::picture::contact::{draw_label, sheet_columns};
    use xylem::picture::Rgb8;
    let arc = LightArc::new(-60.0, 60.0, 30).unwrap();
    let dir = temp_dir("streamed-sheet");
    render_slice(&dir, &arc, 0..30);
    assemble(&dir, &AssembleOptions::default()).unwrap();
    let frames: Vec<Rgb8> = (0..30)
        .map(|i| read_png_rgb8(&dir.join(format!("frame_{i:04}.png"))).unwrap())
        .collect();
    let (cols, gap, (w, h)) = (sheet_columns(30) as u32, 4, (16, 8));
    let rows = 30u32.div_ceil(cols);
    let mut want = Rgb8::filled(
        cols * w + (cols + 1) * gap,
        rows * h + (rows + 1) * gap,
        [24, 24, 24],
    );
    for (i, f) in frames.iter().enumerate() {
        let (c, r) = (i as u32 % cols, i as u32 / cols);
        let (x, y) = (gap + c * (w + gap), gap + r * (h + gap));
        want.blit(f, x, y);
        draw_label(
            &mut want,
            &format!("{:.1}°", arc.angle_deg(i)),
            x + 2,
            y + h - 9,
            1,
        );
    }
    let sheet = read_png_rgb8(&dir.join(CONTACT_SHEET)).unwrap();
    assert_eq!((sheet.width, sheet.height), (want.width, want.height));
    let first_diff = (sheet.data.iter().zip(&want.data))
        .position(|(a, b)| a != b)
        .map(|i| ((i / 3) as u32 % want.width, (i / 3) as u32 / want.width));
    assert_eq!(
        first_diff, None,
        "the sheet's pixels differ from the layout (x, y)"
    );
    let dec = png::Decoder::new(std::fs::File::open(dir.join(ANIMATION)).unwrap());
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    for (i, f) in frames.iter().enumerate() {
        let info = reader.next_frame(&mut buf).unwrap();
        assert!(
            buf[..info.buffer_size()] == f.data[..],
            "animation frame {i}"
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}
