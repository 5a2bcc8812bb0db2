//! The contact sheet: every frame of a sweep as a thumbnail on one grid, each labelled with its
//! light angle, so the highlight's travel can be read at a glance.

use super::image::Rgb8;

/// Columns of a contact sheet for `n` frames: about a 4:3 grid of frames.
pub fn sheet_columns(n: usize) -> usize {
    ((n as f64 * 4.0 / 3.0).sqrt().ceil() as usize).clamp(1, n.max(1))
}

/// Lays out `thumbs` (all the same size) in a grid with `gap` pixels between them and draws each
/// `labels[i]` in the thumbnail's lower-left corner.
pub fn contact_sheet(thumbs: &[Rgb8], labels: &[String], gap: u32) -> Rgb8 {
    contact_sheet_rows(thumbs, labels, sheet_columns(thumbs.len()), gap)
}

/// [`contact_sheet`] with `cols` thumbnails per row: its [`sheet_band`]s one below the other.
pub fn contact_sheet_rows(thumbs: &[Rgb8], labels: &[String], cols: usize, gap: u32) -> Rgb8 {
    let Some(first) = thumbs.first() else {
        return Rgb8::filled(1, 1, [24, 24, 24]);
    };
    let cols = cols.clamp(1, thumbs.len());
    let rows = thumbs.len().div_ceil(cols) as u32;
    let mut data = Vec::new();
    for (r, row) in thumbs.chunks(cols).enumerate() {
        let labels = labels.get(r * cols..).unwrap_or(&[]);
        data.extend(sheet_band(row, labels, cols, gap, r as u32 + 1 == rows).data);
    }
    Rgb8 {
        width: cols as u32 * first.width + (cols as u32 + 1) * gap,
        height: rows * first.height + (rows + 1) * gap,
        data,
    }
}

/// One row of a contact sheet of `cols` columns: the gap above it, `thumbs` (at most `cols`,
/// all one size) with `labels[i]` in each lower-left corner, and, for the `last` row, the gap
/// below. A sheet is its bands one below the other, so a long sweep's sheet can be written band
/// by band. A label of a thumbnail under 9 px tall reaches into the gap above it, never further.
pub fn sheet_band(thumbs: &[Rgb8], labels: &[String], cols: usize, gap: u32, last: bool) -> Rgb8 {
    let Some(first) = thumbs.first() else {
        return Rgb8::filled(1, 1, [24, 24, 24]);
    };
    let (tw, th) = (first.width, first.height);
    let cols = cols.max(1) as u32;
    let below = if last { gap } else { 0 };
    let mut band = Rgb8::filled(cols * tw + (cols + 1) * gap, gap + th + below, [24, 24, 24]);
    for (i, t) in thumbs.iter().enumerate().take(cols as usize) {
        let x = gap + i as u32 * (tw + gap);
        band.blit(t, x, gap);
        if let Some(label) = labels.get(i) {
            let scale = if th >= 96 { 2 } else { 1 };
            let y = (gap + th).saturating_sub(2 + 7 * scale);
            draw_label(&mut band, label, x + 2, y, scale);
        }
    }
    band
}

/// A 3×5 pixel font for labels: digits, sign, point, degree sign, `%`, `_` and the lowercase
/// letters (drawn as capitals, except `e` and `x`) (rows top to bottom, bit 2 = left column).
/// Capitals are drawn as their lowercase glyphs; characters without a glyph as blanks.
fn glyph(c: char) -> [u8; 5] {
    match c.to_ascii_lowercase() {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 7, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 1, 1],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        '-' => [0, 0, 7, 0, 0],
        '+' => [0, 2, 7, 2, 0],
        '.' => [0, 0, 0, 0, 2],
        '°' => [2, 5, 2, 0, 0],
        'e' => [0, 7, 7, 4, 7],
        'x' => [0, 5, 2, 5, 0],
        '%' => [5, 1, 2, 4, 5],
        'a' => [2, 5, 7, 5, 5],
        'b' => [6, 5, 6, 5, 6],
        'c' => [3, 4, 4, 4, 3],
        'd' => [6, 5, 5, 5, 6],
        'f' => [7, 4, 6, 4, 4],
        'g' => [3, 4, 5, 5, 3],
        'h' => [5, 5, 7, 5, 5],
        'i' => [7, 2, 2, 2, 7],
        'j' => [1, 1, 1, 5, 2],
        'k' => [5, 5, 6, 5, 5],
        'l' => [4, 4, 4, 4, 7],
        'm' => [5, 7, 7, 5, 5],
        'n' => [6, 5, 5, 5, 5],
        'o' => [2, 5, 5, 5, 2],
        'p' => [6, 5, 6, 4, 4],
        'q' => [2, 5, 5, 6, 3],
        'r' => [6, 5, 6, 5, 5],
        's' => [3, 4, 2, 1, 6],
        't' => [7, 2, 2, 2, 2],
        'u' => [5, 5, 5, 5, 7],
        'v' => [5, 5, 5, 5, 2],
        'w' => [5, 5, 7, 7, 5],
        'y' => [5, 5, 2, 2, 2],
        'z' => [7, 1, 2, 4, 7],
        '_' => [0, 0, 0, 0, 7],
        _ => [0; 5],
    }
}

/// Draws `text` in white on a dark box with its top-left corner at `(x, y)`, each font pixel
/// `scale × scale` image pixels.
pub fn draw_label(img: &mut Rgb8, text: &str, x: u32, y: u32, scale: u32) {
    let n = text.chars().count() as u32;
    let (w, h) = ((4 * n + 1) * scale, 7 * scale);
    for yy in y..y + h {
        for xx in x..x + w {
            img.put(xx, yy, [0, 0, 0]);
        }
    }
    for (k, c) in text.chars().enumerate() {
        let ox = x + (1 + 4 * k as u32) * scale;
        for (row, bits) in glyph(c).iter().enumerate() {
            for col in 0..3u32 {
                if bits & (4 >> col) != 0 {
                    for dy in 0..scale {
                        for dx in 0..scale {
                            let px = ox + col * scale + dx;
                            let py = y + (1 + row as u32) * scale + dy;
                            img.put(px, py, [255, 255, 255]);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shrinking_averages_in_linear_light() {
        // A 2×1 image of black and white shrinks to one pixel of linear 0.5, i.e. sRGB code 188.
        let img = Rgb8 {
            width: 2,
            height: 1,
            data: vec![0, 0, 0, 255, 255, 255],
        };
        let s = img.shrink_to_width(1);
        assert_eq!((s.width, s.height), (1, 1));
        assert_eq!(s.data, vec![188, 188, 188]);
        assert_eq!(img.shrink_to_width(5), img);
    }

    #[test]
    fn sheet_grid_holds_every_frame() {
        for n in [1usize, 2, 5, 12, 48, 49, 100] {
            let c = sheet_columns(n);
            assert!(c * n.div_ceil(c) >= n && c <= n);
        }
        assert_eq!(sheet_columns(48), 8);
        let thumbs: Vec<Rgb8> = (0..5)
            .map(|i| Rgb8::filled(10, 6, [i * 50, 0, 0]))
            .collect();
        let sheet = contact_sheet(&thumbs, &[], 2);
        // 3 columns, 2 rows: 3·10 + 4·2 by 2·6 + 3·2.
        assert_eq!((sheet.width, sheet.height), (38, 18));
        // The 5th thumbnail (red 200) sits in row 1, column 1.
        let (x, y) = (2 + 12 + 3, 2 + 8 + 3);
        let i = (y * 38 + x) as usize * 3;
        assert_eq!(&sheet.data[i..i + 3], &[200, 0, 0]);
    }

    #[test]
    fn labels_draw_inside_their_box() {
        let mut img = Rgb8::filled(40, 12, [100, 100, 100]);
        draw_label(&mut img, "-7.5°", 1, 1, 1);
        let white = img.data.chunks(3).filter(|p| p == &[255, 255, 255]).count();
        // '-' 3 + '7' 7 + '.' 1 + '5' 11 + '°' 4 lit font pixels.
        assert_eq!(white, 26);
        assert_eq!(
            &img.data[..3],
            &[100, 100, 100],
            "outside the box is untouched"
        );
    }
}
