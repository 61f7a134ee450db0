//! A minimal SVG plot: data coordinates in millimetres (or grades) mapped onto a framed area with
//! ticks, axis labels, a title and a legend. Hand-written because the figures are line drawings
//! of slices, not statistical charts.

use std::fmt::Write;

/// A figure with one plot area.
pub struct Plot {
    width: f64,
    height: f64,
    margin: (f64, f64, f64, f64),
    x: (f64, f64),
    y: (f64, f64),
    body: String,
    legend: Vec<(String, String)>,
    title: String,
    labels: (String, String),
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Narrowest figure `[px]`: room for a title of about 80 characters.
const MIN_WIDTH: f64 = 600.0;

/// Rounded tick step for a span.
fn tick_step(span: f64) -> f64 {
    let raw = span / 6.0;
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * p)
}

impl Plot {
    /// A plot of the data ranges `x` and `y`; with `equal` the scales are made equal (for
    /// slices, so shapes are not distorted).
    pub fn new(
        title: &str,
        x_label: &str,
        y_label: &str,
        x: (f64, f64),
        y: (f64, f64),
        equal: bool,
    ) -> Plot {
        let (mut x, mut y) = (x, y);
        if x.1 - x.0 <= 0.0 {
            x = (x.0 - 1.0, x.0 + 1.0);
        }
        if y.1 - y.0 <= 0.0 {
            y = (y.0 - 1.0, y.0 + 1.0);
        }
        let margin = (60.0, 20.0, 40.0, 50.0);
        let (mut width, mut height) = (640.0, 480.0);
        if equal {
            let plot_w = width - margin.0 - margin.1;
            let scale = plot_w / (x.1 - x.0);
            height = (y.1 - y.0) * scale + margin.2 + margin.3;
            if height > 900.0 {
                let plot_h = 900.0 - margin.2 - margin.3;
                let scale = plot_h / (y.1 - y.0);
                height = 900.0;
                width = (x.1 - x.0) * scale + margin.0 + margin.1;
                // A tall, thin object: widen the x range (same scale) so that the title and the
                // legend still fit.
                if width < MIN_WIDTH {
                    let extra = (MIN_WIDTH - width) / scale / 2.0;
                    x = (x.0 - extra, x.1 + extra);
                    width = MIN_WIDTH;
                }
            }
        }
        Plot {
            width,
            height,
            margin,
            x,
            y,
            body: String::new(),
            legend: Vec::new(),
            title: title.to_string(),
            labels: (x_label.to_string(), y_label.to_string()),
        }
    }

    fn px(&self, x: f64) -> f64 {
        self.margin.0
            + (x - self.x.0) / (self.x.1 - self.x.0) * (self.width - self.margin.0 - self.margin.1)
    }

    fn py(&self, y: f64) -> f64 {
        self.height
            - self.margin.3
            - (y - self.y.0) / (self.y.1 - self.y.0) * (self.height - self.margin.2 - self.margin.3)
    }

    /// A polyline (closed when `closed`), with a CSS class naming the series.
    pub fn polyline(
        &mut self,
        points: &[(f64, f64)],
        color: &str,
        width: f64,
        closed: bool,
        class: &str,
    ) {
        if points.is_empty() {
            return;
        }
        let pts: Vec<String> = points
            .iter()
            .map(|(x, y)| format!("{:.2},{:.2}", self.px(*x), self.py(*y)))
            .collect();
        let tag = if closed { "polygon" } else { "polyline" };
        let _ = writeln!(
            self.body,
            "<{tag} class=\"{class}\" points=\"{}\" fill=\"none\" stroke=\"{color}\" stroke-width=\"{width}\"/>",
            pts.join(" ")
        );
    }

    /// A filled polygon.
    pub fn fill(&mut self, points: &[(f64, f64)], color: &str, opacity: f64, class: &str) {
        let pts: Vec<String> = points
            .iter()
            .map(|(x, y)| format!("{:.2},{:.2}", self.px(*x), self.py(*y)))
            .collect();
        let _ = writeln!(
            self.body,
            "<polygon class=\"{class}\" points=\"{}\" fill=\"{color}\" fill-opacity=\"{opacity}\" stroke=\"none\"/>",
            pts.join(" ")
        );
    }

    /// A segment.
    pub fn line(
        &mut self,
        a: (f64, f64),
        b: (f64, f64),
        color: &str,
        width: f64,
        dash: bool,
        class: &str,
    ) {
        let _ = writeln!(
            self.body,
            "<line class=\"{class}\" x1=\"{:.2}\" y1=\"{:.2}\" x2=\"{:.2}\" y2=\"{:.2}\" stroke=\"{color}\" stroke-width=\"{width}\"{}/>",
            self.px(a.0),
            self.py(a.1),
            self.px(b.0),
            self.py(b.1),
            if dash { " stroke-dasharray=\"4 3\"" } else { "" }
        );
    }

    /// A marker of radius `r` pixels.
    pub fn dot(&mut self, p: (f64, f64), r: f64, color: &str, class: &str) {
        let _ = writeln!(
            self.body,
            "<circle class=\"{class}\" cx=\"{:.2}\" cy=\"{:.2}\" r=\"{r}\" fill=\"{color}\"/>",
            self.px(p.0),
            self.py(p.1)
        );
    }

    /// A circle of radius `r` in data units (outline).
    pub fn circle(&mut self, c: (f64, f64), r: f64, color: &str, class: &str) {
        let rx = r / (self.x.1 - self.x.0) * (self.width - self.margin.0 - self.margin.1);
        let _ = writeln!(
            self.body,
            "<circle class=\"{class}\" cx=\"{:.2}\" cy=\"{:.2}\" r=\"{rx:.2}\" fill=\"none\" stroke=\"{color}\" stroke-width=\"1\" stroke-dasharray=\"3 3\"/>",
            self.px(c.0),
            self.py(c.1)
        );
    }

    /// A horizontal bar from x = 0 to `value` at `y`, `thickness` data units tall.
    pub fn hbar(&mut self, y: f64, value: f64, thickness: f64, color: &str, class: &str) {
        let (x0, x1) = (self.px(0.0f64.min(value)), self.px(0.0f64.max(value)));
        let (y0, y1) = (self.py(y + thickness / 2.0), self.py(y - thickness / 2.0));
        let _ = writeln!(
            self.body,
            "<rect class=\"{class}\" x=\"{x0:.2}\" y=\"{y0:.2}\" width=\"{:.2}\" height=\"{:.2}\" fill=\"{color}\"/>",
            (x1 - x0).max(0.5),
            (y1 - y0).max(0.5)
        );
    }

    /// Text at a data point.
    pub fn text(&mut self, p: (f64, f64), s: &str, size: f64) {
        let _ = writeln!(
            self.body,
            "<text x=\"{:.2}\" y=\"{:.2}\" font-size=\"{size}\" font-family=\"sans-serif\">{}</text>",
            self.px(p.0) + 4.0,
            self.py(p.1) - 4.0,
            esc(s)
        );
    }

    /// Adds a legend entry.
    pub fn legend(&mut self, label: &str, color: &str) {
        self.legend.push((label.to_string(), color.to_string()));
    }

    /// The SVG document. The legend sits in a band of its own between the title and the plot
    /// frame, so it neither covers data nor runs off the figure's edge; everything drawn in data
    /// coordinates is clipped to the frame, so nothing spills over the titles.
    pub fn finish(&self) -> String {
        let mut s = String::new();
        let band = legend_band(&self.legend, self.width);
        self.write_title_and_legend(&mut s, &band);
        let _ = writeln!(s, "<g transform=\"translate(0 {:.0})\">", band.height);
        // The frame in pixels, within the plot's own height (below the legend band).
        let frame = (
            self.margin.0,
            self.width - self.margin.1,
            self.margin.2,
            self.height - self.margin.3,
        );
        self.write_frame_and_ticks(&mut s, frame);
        self.write_axis_labels(&mut s, frame);
        let (l, r, t, b) = frame;
        // A clip id unique to this figure (the page inlines several SVGs, and ids are global
        // there), derived from the title so that the output is deterministic.
        let id = format!("frame-{:016x}", fnv1a(self.title.as_bytes()));
        let _ = writeln!(
            s,
            "<clipPath id=\"{id}\"><rect x=\"{l:.1}\" y=\"{t:.1}\" width=\"{:.1}\" height=\"{:.1}\"/></clipPath>",
            r - l,
            b - t
        );
        let _ = writeln!(s, "<g clip-path=\"url(#{id})\">");
        s.push_str(&self.body);
        s.push_str("</g>\n</g>\n</svg>\n");
        s
    }

    /// The document's opening tag (its height with the legend `band`), the white background,
    /// the title, and the legend entries.
    fn write_title_and_legend(&self, s: &mut String, band: &LegendBand) {
        let (w, h) = (self.width, self.height + band.height);
        let _ = writeln!(
            s,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w:.0}\" height=\"{h:.0}\" viewBox=\"0 0 {w:.0} {h:.0}\">"
        );
        let _ = writeln!(s, "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>");
        let _ = writeln!(
            s,
            "<text x=\"{:.0}\" y=\"22\" font-size=\"15\" font-family=\"sans-serif\" text-anchor=\"middle\">{}</text>",
            w / 2.0,
            esc(&self.title)
        );
        for (label, color, x, y) in &band.entries {
            let _ = writeln!(
                s,
                "<rect x=\"{x:.0}\" y=\"{:.0}\" width=\"12\" height=\"4\" fill=\"{color}\"/><text class=\"legend\" x=\"{:.0}\" y=\"{:.0}\" font-size=\"11\" font-family=\"sans-serif\">{}</text>",
                y - 4.0,
                x + 18.0,
                y + 1.0,
                esc(label)
            );
        }
    }

    /// The plot frame (`left, right, top, bottom` in pixels), with a grid line and a label at
    /// each tick of both axes.
    fn write_frame_and_ticks(&self, s: &mut String, (l, r, t, b): (f64, f64, f64, f64)) {
        let _ = writeln!(
            s,
            "<rect x=\"{l:.1}\" y=\"{t:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"none\" stroke=\"black\"/>",
            r - l,
            b - t
        );
        let sx = tick_step(self.x.1 - self.x.0);
        let mut v = (self.x.0 / sx).ceil() * sx;
        while v <= self.x.1 + 1e-9 {
            let x = self.px(v);
            let _ = writeln!(
                s,
                "<line x1=\"{x:.1}\" y1=\"{t:.1}\" x2=\"{x:.1}\" y2=\"{b:.1}\" stroke=\"#ddd\"/><text x=\"{x:.1}\" y=\"{:.1}\" font-size=\"11\" font-family=\"sans-serif\" text-anchor=\"middle\">{}</text>",
                b + 14.0,
                fmt_tick(v)
            );
            v += sx;
        }
        let sy = tick_step(self.y.1 - self.y.0);
        let mut v = (self.y.0 / sy).ceil() * sy;
        while v <= self.y.1 + 1e-9 {
            let y = self.py(v);
            let _ = writeln!(
                s,
                "<line x1=\"{l:.1}\" y1=\"{y:.1}\" x2=\"{r:.1}\" y2=\"{y:.1}\" stroke=\"#ddd\"/><text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" font-family=\"sans-serif\" text-anchor=\"end\">{}</text>",
                l - 4.0,
                y + 4.0,
                fmt_tick(v)
            );
            v += sy;
        }
    }

    /// The x axis's label under the frame and the y axis's, turned, left of it.
    fn write_axis_labels(&self, s: &mut String, (l, r, t, b): (f64, f64, f64, f64)) {
        let _ = writeln!(
            s,
            "<text x=\"{:.0}\" y=\"{:.0}\" font-size=\"12\" font-family=\"sans-serif\" text-anchor=\"middle\">{}</text>",
            (l + r) / 2.0,
            self.height - 12.0,
            esc(&self.labels.0)
        );
        let _ = writeln!(
            s,
            "<text x=\"14\" y=\"{:.0}\" font-size=\"12\" font-family=\"sans-serif\" text-anchor=\"middle\" transform=\"rotate(-90 14 {:.0})\">{}</text>",
            (t + b) / 2.0,
            (t + b) / 2.0,
            esc(&self.labels.1)
        );
    }
}

/// Where the legend entries go: rows between the title and the frame, as many entries to a row
/// as fit the figure's width.
struct LegendBand {
    height: f64,
    entries: Vec<(String, String, f64, f64)>,
}

fn legend_band(legend: &[(String, String)], width: f64) -> LegendBand {
    // 11 px sans-serif: about 6.2 px a character, plus the swatch and a gap.
    let (left, right) = (60.0, width - 10.0);
    let (mut x, mut row) = (left, 0usize);
    let mut entries = Vec::new();
    for (label, color) in legend {
        let w = 18.0 + 6.2 * label.chars().count() as f64 + 16.0;
        if x > left && x + w > right {
            row += 1;
            x = left;
        }
        entries.push((label.clone(), color.clone(), x, 44.0 + 16.0 * row as f64));
        x += w;
    }
    let height = if legend.is_empty() {
        0.0
    } else {
        16.0 * (row + 1) as f64 + 6.0
    };
    LegendBand { height, entries }
}

/// FNV-1a, 64 bits: a stable hash for ids.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3)
    })
}

fn fmt_tick(v: f64) -> String {
    let r = (v * 1000.0).round() / 1000.0;
    if r == r.trunc() {
        format!("{}", r as i64)
    } else {
        format!("{r}")
    }
}
