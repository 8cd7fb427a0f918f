//! Two pictures of a measured look ([`crate::look::Look`]) that people read at a glance:
//! - **side view**: the centre column seen edge-on over one drive period, one profile per
//!   frame coloured by the phase of the drive, drawn to scale (metres on both axes);
//! - **space-time plot**: depth down the column against time, coloured by the out-of-plane
//!   displacement from the row's mean: a bump travelling down draws a diagonal stripe, the
//!   whole cloth bending as one draws vertical bands.

use tiny_skia::{Color, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

use super::label::{draw_text, text_width};
use fraccloth_tools::look::Look;

const INK: [u8; 3] = [30, 30, 30];
const BACKGROUND: Color = Color::WHITE;
const MARGIN_LEFT: f32 = 58.0;
const MARGIN_RIGHT: f32 = 14.0;
const MARGIN_TOP: f32 = 34.0;
const MARGIN_BOTTOM: f32 = 40.0;

/// A rectangle of the picture mapped to a range of data.
struct Axes {
    x0: f32,
    y0: f32,
    w: f32,
    h: f32,
    /// Data range shown: (x_min, x_max, y_min, y_max).
    range: (f64, f64, f64, f64),
    /// y grows downward (depths) rather than upward (heights).
    down: bool,
}

impl Axes {
    fn px(&self, x: f64, y: f64) -> (f32, f32) {
        let (a, b, c, d) = self.range;
        let fy = if self.down {
            (y - c) / (d - c)
        } else {
            (d - y) / (d - c)
        };
        (
            self.x0 + self.w * ((x - a) / (b - a)) as f32,
            self.y0 + self.h * fy as f32,
        )
    }
}

fn paint(rgb: [u8; 3]) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(rgb[0], rgb[1], rgb[2], 255);
    p.anti_alias = true;
    p
}

fn line(pix: &mut Pixmap, pts: &[(f32, f32)], rgb: [u8; 3], width: f32) {
    let mut pb = PathBuilder::new();
    for (k, &(x, y)) in pts.iter().enumerate() {
        if k == 0 {
            pb.move_to(x, y);
        } else {
            pb.line_to(x, y);
        }
    }
    if let Some(path) = pb.finish() {
        let stroke = Stroke {
            width,
            ..Stroke::default()
        };
        pix.stroke_path(&path, &paint(rgb), &stroke, Transform::identity(), None);
    }
}

/// Round tick spacing for a span.
fn tick_step(span: f64) -> f64 {
    let raw = span / 5.0;
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * p)
}

fn fmt_tick(v: f64, step: f64) -> String {
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    // A tick at zero reached by adding steps may be -1e-17: print it as 0.
    let v = if v.abs() < 1e-6 * step { 0.0 } else { v };
    format!("{v:.decimals$}")
}

/// Frame, ticks, tick labels and axis titles.
fn draw_axes(pix: &mut Pixmap, ax: &Axes, x_title: &str, y_title: &str, x_scale: f64, y_scale: f64) {
    let (a, b, c, d) = ax.range;
    let frame = [
        (ax.x0, ax.y0),
        (ax.x0 + ax.w, ax.y0),
        (ax.x0 + ax.w, ax.y0 + ax.h),
        (ax.x0, ax.y0 + ax.h),
        (ax.x0, ax.y0),
    ];
    line(pix, &frame, INK, 1.0);
    let sx = tick_step((b - a) * x_scale) / x_scale;
    let mut v = (a / sx).ceil() * sx;
    while v <= b + 1e-9 * sx {
        let (x, _) = ax.px(v, c);
        let y = ax.y0 + ax.h;
        line(pix, &[(x, y), (x, y + 4.0)], INK, 1.0);
        let label = fmt_tick(v * x_scale, sx * x_scale);
        let tx = (x - text_width(&label, 1) as f32 / 2.0).max(0.0) as u32;
        draw_text(pix, &label, tx, (y + 7.0) as u32, 1, INK);
        v += sx;
    }
    let sy = tick_step((d - c) * y_scale) / y_scale;
    let mut v = (c / sy).ceil() * sy;
    while v <= d + 1e-9 * sy {
        let (x, y) = ax.px(a, v);
        line(pix, &[(x - 4.0, y), (x, y)], INK, 1.0);
        let label = fmt_tick(v * y_scale, sy * y_scale);
        let tx = (x - 6.0 - text_width(&label, 1) as f32).max(0.0) as u32;
        draw_text(pix, &label, tx, (y - 4.0).max(0.0) as u32, 1, INK);
        v += sy;
    }
    let tx = ax.x0 + ax.w / 2.0 - text_width(x_title, 1) as f32 / 2.0;
    draw_text(
        pix,
        x_title,
        tx.max(0.0) as u32,
        (ax.y0 + ax.h + 22.0) as u32,
        1,
        INK,
    );
    draw_text(pix, y_title, 4, (ax.y0 - 14.0).max(0.0) as u32, 1, INK);
}

/// A cyclic colour for a phase in [0, 1): hue around the colour wheel.
pub fn phase_colour(phase: f64) -> [u8; 3] {
    let h = phase.rem_euclid(1.0) * 6.0;
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    let (r, g, b) = match h as u32 {
        0 => (1.0, x, 0.0),
        1 => (x, 1.0, 0.0),
        2 => (0.0, 1.0, x),
        3 => (0.0, x, 1.0),
        4 => (x, 0.0, 1.0),
        _ => (1.0, 0.0, x),
    };
    // Darkened so that the yellows and cyans read on white.
    let c = |v: f64| (40.0 + 170.0 * v) as u8;
    [c(r), c(g), c(b)]
}

/// A diverging colour for a value in [-1, 1]: blue, white, red.
pub fn diverging_colour(v: f64) -> [u8; 3] {
    let v = v.clamp(-1.0, 1.0);
    let lerp = |a: f64, b: f64, t: f64| (a + (b - a) * t).round() as u8;
    if v >= 0.0 {
        [lerp(247.0, 178.0, v), lerp(247.0, 24.0, v), lerp(247.0, 43.0, v)]
    } else {
        [
            lerp(247.0, 33.0, -v),
            lerp(247.0, 102.0, -v),
            lerp(247.0, 172.0, -v),
        ]
    }
}

/// The centre column seen from the side over the last drive period of the measured window,
/// to scale; a `width` x `height` picture with a title.
pub fn side_view(look: &Look, title: &str, width: u32, height: u32) -> Option<Pixmap> {
    let mut pix = Pixmap::new(width, height)?;
    pix.fill(BACKGROUND);
    let m = &look.motion;
    let (t0, t1, periods) = look.window;
    let period = (t1 - t0) / f64::from(periods.max(1));
    let frames: Vec<usize> = (0..m.times.len())
        .filter(|&k| m.times[k] >= t1 - period - 1e-9)
        .collect();
    let n = m.frames();
    if frames.is_empty() || n == 0 {
        return None;
    }
    // Positions relative to the top row's mean over the window.
    let top_off = m.offsets.iter().map(|f| f[0]).sum::<f64>() / n as f64;
    let top_h = m.heights.iter().map(|f| f[0]).sum::<f64>() / n as f64;
    let (mut xr, mut yr) = (0.02f64, 0.05f64);
    for &k in &frames {
        for (o, h) in m.offsets[k].iter().zip(&m.heights[k]) {
            xr = xr.max((o - top_off).abs());
            yr = yr.max(top_h - h);
        }
    }
    let (pw, ph) = (
        width as f32 - MARGIN_LEFT - MARGIN_RIGHT,
        height as f32 - MARGIN_TOP - MARGIN_BOTTOM,
    );
    // Equal scale on both axes: widen whichever range the box leaves room for.
    let ymax = 0.01 * yr.max(0.0);
    let (mut xspan, mut yspan) = (2.2 * xr, 1.05 * yr + ymax);
    let scale = (pw as f64 / xspan).min(ph as f64 / yspan);
    xspan = pw as f64 / scale;
    yspan = ph as f64 / scale;
    let ax = Axes {
        x0: MARGIN_LEFT,
        y0: MARGIN_TOP,
        w: pw,
        h: ph,
        range: (-xspan / 2.0, xspan / 2.0, ymax - yspan, ymax),
        down: false,
    };
    // Rest line of the top (x = 0).
    line(
        &mut pix,
        &[ax.px(0.0, ax.range.2), ax.px(0.0, ax.range.3)],
        [200, 200, 200],
        1.0,
    );
    for &k in &frames {
        let phase = ((m.times[k] - (t1 - period)) / period).clamp(0.0, 0.999);
        let pts: Vec<(f32, f32)> = m.offsets[k]
            .iter()
            .zip(&m.heights[k])
            .map(|(o, h)| ax.px(o - top_off, h - top_h))
            .collect();
        line(&mut pix, &pts, phase_colour(phase), 1.5);
    }
    draw_axes(
        &mut pix,
        &ax,
        "out-of-plane displacement (cm)",
        "height (cm)",
        100.0,
        100.0,
    );
    draw_text(&mut pix, title, 4, 4, 1, INK);
    // Phase key: a strip of the cyclic colours, 0 to 1 period.
    let (kx, ky) = (width.saturating_sub(110), 18);
    draw_text(&mut pix, "phase 0..1", kx, 4, 1, INK);
    for i in 0..100u32 {
        let c = phase_colour(f64::from(i) / 100.0);
        if let Some(r) = Rect::from_xywh((kx + i) as f32, ky as f32, 1.0, 8.0) {
            pix.fill_rect(r, &paint(c), Transform::identity(), None);
        }
    }
    Some(pix)
}

/// Depth against time over the whole cache, coloured by the out-of-plane displacement from
/// each row's mean over the measured window (blue one way, red the other, white none); a
/// `width` x `height` picture with a title and a colour key.
pub fn space_time(look: &Look, title: &str, width: u32, height: u32) -> Option<Pixmap> {
    let mut pix = Pixmap::new(width, height)?;
    pix.fill(BACKGROUND);
    let (h, m) = (&look.history, &look.motion);
    let rows = h.depths.len();
    let frames = h.frames();
    if rows < 2 || frames < 2 || m.frames() == 0 {
        return None;
    }
    let mean: Vec<f64> = (0..rows)
        .map(|j| m.offsets.iter().map(|f| f[j]).sum::<f64>() / m.frames() as f64)
        .collect();
    let scale = 1.2 * look.descriptors.top_amplitude.max(1e-6);
    let (t_first, t_last) = (h.times[0], h.times[frames - 1]);
    let depth = h.depths[rows - 1];
    let ax = Axes {
        x0: MARGIN_LEFT,
        y0: MARGIN_TOP,
        w: width as f32 - MARGIN_LEFT - MARGIN_RIGHT - 40.0,
        h: height as f32 - MARGIN_TOP - MARGIN_BOTTOM,
        range: (t_first, t_last, 0.0, depth),
        down: true,
    };
    // One cell per frame and row, nearest-sample.
    let dt = (t_last - t_first) / (frames - 1) as f64;
    for k in 0..frames {
        let (xa, _) = ax.px(h.times[k] - 0.5 * dt, 0.0);
        let (xb, _) = ax.px(h.times[k] + 0.5 * dt, 0.0);
        for j in 0..rows {
            let ya = if j == 0 {
                0.0
            } else {
                0.5 * (h.depths[j - 1] + h.depths[j])
            };
            let yb = if j + 1 == rows {
                depth
            } else {
                0.5 * (h.depths[j] + h.depths[j + 1])
            };
            let (_, pa) = ax.px(0.0, ya);
            let (_, pb) = ax.px(0.0, yb);
            let c = diverging_colour((h.offsets[k][j] - mean[j]) / scale);
            let (x, w) = (xa.max(ax.x0), xb.min(ax.x0 + ax.w) - xa.max(ax.x0));
            if let Some(r) = Rect::from_xywh(x, pa, w.max(0.5), (pb - pa).max(0.5)) {
                pix.fill_rect(r, &paint(c), Transform::identity(), None);
            }
        }
    }
    // The measured window starts here.
    let (xw, _) = ax.px(look.window.0, 0.0);
    line(&mut pix, &[(xw, ax.y0), (xw, ax.y0 + ax.h)], [0, 0, 0], 1.0);
    draw_axes(&mut pix, &ax, "time (s)", "depth (cm)", 1.0, 100.0);
    draw_text(&mut pix, title, 4, 4, 1, INK);
    // Colour key.
    let kx = (ax.x0 + ax.w + 14.0) as u32;
    let (ky, kh) = (ax.y0 as u32, ax.h as u32);
    for i in 0..kh {
        let v = 1.0 - 2.0 * f64::from(i) / f64::from(kh.max(1));
        if let Some(r) = Rect::from_xywh(kx as f32, (ky + i) as f32, 10.0, 1.0) {
            pix.fill_rect(r, &paint(diverging_colour(v)), Transform::identity(), None);
        }
    }
    let cm = format!("{:.1}", 100.0 * scale);
    draw_text(
        &mut pix,
        &format!("+{cm}"),
        kx.saturating_sub(4),
        ky.saturating_sub(10),
        1,
        INK,
    );
    draw_text(
        &mut pix,
        &format!("-{cm}"),
        kx.saturating_sub(4),
        ky + kh + 3,
        1,
        INK,
    );
    draw_text(&mut pix, "cm", kx, ky + kh + 13, 1, INK);
    Some(pix)
}
