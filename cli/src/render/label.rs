//! Text labels from the public-domain 8x8 bitmap font of `font8x8`.

use font8x8::{UnicodeFonts, BASIC_FONTS};
use tiny_skia::{Pixmap, PremultipliedColorU8};

/// Draws `text` with its top-left corner at (x, y), each font pixel `scale` x `scale`, white.
pub fn draw_label(pix: &mut Pixmap, text: &str, x: u32, y: u32, scale: u32) {
    draw_text(pix, text, x, y, scale, [255, 255, 255]);
}

/// Width of `text` drawn at `scale`, px.
pub fn text_width(text: &str, scale: u32) -> u32 {
    8 * scale * text.chars().count() as u32
}

/// Draws `text` with its top-left corner at (x, y), each font pixel `scale` x `scale`, in an
/// opaque colour.
pub fn draw_text(pix: &mut Pixmap, text: &str, x: u32, y: u32, scale: u32, rgb: [u8; 3]) {
    let (w, h) = (pix.width(), pix.height());
    let white = PremultipliedColorU8::from_rgba(rgb[0], rgb[1], rgb[2], 255)
        .unwrap_or(PremultipliedColorU8::TRANSPARENT);
    let pixels = pix.pixels_mut();
    for (k, ch) in text.chars().enumerate() {
        let glyph = BASIC_FONTS.get(ch).unwrap_or([0; 8]);
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8u32 {
                if bits & (1 << col) == 0 {
                    continue;
                }
                for dy in 0..scale {
                    for dx in 0..scale {
                        let px = x + (k as u32 * 8 + col) * scale + dx;
                        let py = y + row as u32 * scale + dy;
                        if px < w && py < h {
                            pixels[(py * w + px) as usize] = white;
                        }
                    }
                }
            }
        }
    }
}
