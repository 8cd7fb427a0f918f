//! Contact sheets (a grid of frames with labels) and animated GIFs.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use tiny_skia::{Color, Pixmap, PixmapPaint, Transform};

use super::draw_label;

/// Height of a label strip, px.
const STRIP: u32 = 22;

/// Lays `rows` of equally sized cells into one picture, with a label above each column and
/// one at the left of each row (either list may be empty).
pub fn contact_sheet(
    rows: &[Vec<Pixmap>],
    column_labels: &[String],
    row_labels: &[String],
) -> Option<Pixmap> {
    let first = rows.first()?.first()?;
    let (cw, ch) = (first.width(), first.height());
    let ncols = rows.iter().map(Vec::len).max()? as u32;
    let left = if row_labels.is_empty() {
        0
    } else {
        8 * 2 * row_labels.iter().map(|l| l.len()).max().unwrap_or(0) as u32 + 8
    };
    let top = if column_labels.is_empty() { 0 } else { STRIP };
    let gap = 2;
    let mut sheet = Pixmap::new(left + ncols * (cw + gap), top + rows.len() as u32 * (ch + gap))?;
    sheet.fill(Color::from_rgba8(12, 16, 24, 255));
    for (c, label) in column_labels.iter().enumerate() {
        draw_label(&mut sheet, label, left + c as u32 * (cw + gap) + 4, 3, 2);
    }
    for (r, row) in rows.iter().enumerate() {
        let y = top + r as u32 * (ch + gap);
        if let Some(label) = row_labels.get(r) {
            draw_label(&mut sheet, label, 4, y + ch / 2 - 8, 2);
        }
        for (c, cell) in row.iter().enumerate() {
            let x = left + c as u32 * (cw + gap);
            sheet.draw_pixmap(
                x as i32,
                y as i32,
                cell.as_ref(),
                &PixmapPaint::default(),
                Transform::identity(),
                None,
            );
        }
    }
    Some(sheet)
}

/// Streams frames into an endlessly looping GIF.
pub struct GifWriter {
    encoder: gif::Encoder<BufWriter<File>>,
    width: u16,
    height: u16,
    delay: u16,
}

impl GifWriter {
    /// `frame_seconds` is how long each frame shows.
    pub fn create(path: &Path, width: u32, height: u32, frame_seconds: f64) -> std::io::Result<Self> {
        let bad = |m: &str| std::io::Error::new(std::io::ErrorKind::InvalidInput, m.to_string());
        let w = u16::try_from(width).map_err(|_| bad("GIF too wide"))?;
        let h = u16::try_from(height).map_err(|_| bad("GIF too tall"))?;
        let mut encoder = gif::Encoder::new(BufWriter::new(File::create(path)?), w, h, &[])
            .map_err(std::io::Error::other)?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(std::io::Error::other)?;
        Ok(Self {
            encoder,
            width: w,
            height: h,
            delay: (frame_seconds * 100.0).round().max(2.0) as u16,
        })
    }

    /// Appends one frame (must be the size given at creation; opaque).
    pub fn push(&mut self, pix: &Pixmap) -> std::io::Result<()> {
        if pix.width() != u32::from(self.width) || pix.height() != u32::from(self.height) {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "frame size differs",
            ));
        }
        let mut rgba = pix.data().to_vec(); // opaque: premultiplied equals straight alpha
        let mut frame = gif::Frame::from_rgba_speed(self.width, self.height, &mut rgba, 20);
        frame.delay = self.delay;
        self.encoder.write_frame(&frame).map_err(std::io::Error::other)
    }
}

/// Saves a pixmap as PNG.
pub fn save_png(pix: &Pixmap, path: &Path) -> std::io::Result<()> {
    pix.save_png(path).map_err(std::io::Error::other)
}
