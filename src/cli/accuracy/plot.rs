//! A small dependency-free SVG line plot: one or more series of labelled points on linear or
//! logarithmic axes with ticks, tick labels and axis titles — enough for the accuracy plot
//! (error against time, both logarithmic) and viewable in any browser.

use std::fmt::Write as _;
use std::path::Path;

use cylvol::Error;

/// How an axis maps values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Scale {
    /// Evenly spaced values.
    #[default]
    Linear,
    /// Evenly spaced decades (values must be positive).
    Log,
}

/// A series: points joined by a line, each marked and optionally labelled.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Series {
    /// Legend name.
    pub name: String,
    /// `(x, y)` points, joined in this order.
    pub points: Vec<(f64, f64)>,
    /// A label per point (missing or empty labels are not drawn).
    pub labels: Vec<String>,
}

/// A line plot.
#[derive(Clone, Debug, PartialEq)]
pub struct Plot {
    /// Title above the plot area.
    pub title: String,
    /// Horizontal axis title.
    pub x_label: String,
    /// Vertical axis title.
    pub y_label: String,
    /// Horizontal scale.
    pub x_scale: Scale,
    /// Vertical scale.
    pub y_scale: Scale,
    /// The series, drawn in order.
    pub series: Vec<Series>,
    /// Width of the picture in pixels (default 720).
    pub width: u32,
    /// Height of the picture in pixels (default 480).
    pub height: u32,
}

impl Default for Plot {
    fn default() -> Plot {
        Plot {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            series: Vec::new(),
            width: 720,
            height: 480,
        }
    }
}

const COLORS: [&str; 6] = [
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf",
];

/// Escapes text for XML content and attribute values.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c if (c as u32) < 0x20 && c != '\t' && c != '\n' => {}
            c => out.push(c),
        }
    }
    out
}

/// A tick value as short text: `0.002`, `5`, `1e-05`, `2e+06`.
fn tick_text(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".into()
    } else if (1e-3..1e5).contains(&a) {
        format!("{}", (v * 1e9).round() / 1e9)
    } else {
        let s = format!("{v:e}");
        // Rust writes `1e-5`, `2.5e6`: keep it.
        s
    }
}

/// One axis after fitting: the mapped range and its ticks.
struct Fitted {
    scale: Scale,
    lo: f64,
    hi: f64,
    /// `(value, labelled)`.
    ticks: Vec<(f64, bool)>,
}

impl Fitted {
    fn map(&self, v: f64) -> f64 {
        match self.scale {
            Scale::Linear => v,
            Scale::Log => v.log10(),
        }
    }

    /// Fraction of the way from `lo` to `hi`.
    fn frac(&self, v: f64) -> f64 {
        let (a, b) = (self.map(self.lo), self.map(self.hi));
        if b > a {
            (self.map(v) - a) / (b - a)
        } else {
            0.5
        }
    }
}

/// Fits an axis to values, with margins and ticks.
fn fit(values: &[f64], scale: Scale, name: &str) -> Result<Fitted, Error> {
    if values.iter().any(|v| !v.is_finite()) {
        return Err(Error::Invalid(format!(
            "plot: a {name} value is not finite"
        )));
    }
    if scale == Scale::Log && values.iter().any(|&v| v <= 0.0) {
        return Err(Error::Invalid(format!(
            "plot: a {name} value is not positive on a logarithmic axis"
        )));
    }
    let (mut lo, mut hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if values.is_empty() {
        (lo, hi) = match scale {
            Scale::Linear => (0.0, 1.0),
            Scale::Log => (1.0, 10.0),
        };
    }
    match scale {
        Scale::Linear => {
            let span = if hi > lo { hi - lo } else { lo.abs().max(1.0) };
            lo -= 0.08 * span;
            hi += 0.08 * span;
            let raw = (hi - lo) / 6.0;
            let mag = 10f64.powf(raw.log10().floor());
            let step = [1.0, 2.0, 5.0, 10.0]
                .iter()
                .map(|m| m * mag)
                .find(|s| *s >= raw)
                .unwrap_or(10.0 * mag);
            let first = (lo / step).ceil() as i64;
            let last = (hi / step).floor() as i64;
            let ticks = (first..=last).map(|k| (k as f64 * step, true)).collect();
            Ok(Fitted {
                scale,
                lo,
                hi,
                ticks,
            })
        }
        Scale::Log => {
            let (mut a, mut b) = (lo.log10(), hi.log10());
            let span = if b > a { b - a } else { 1.0 };
            a -= 0.08 * span;
            b += 0.08 * span;
            let decades = b - a;
            let mut ticks = Vec::new();
            for e in (a.floor() as i32)..=(b.ceil() as i32) {
                for m in 1..10 {
                    let v: f64 = format!("{m}e{e}").parse().unwrap_or(f64::NAN);
                    let l = v.log10();
                    if l < a || l > b {
                        continue;
                    }
                    let labelled =
                        m == 1 || (decades <= 2.5 && (m == 2 || m == 5)) || (decades <= 1.2);
                    ticks.push((v, labelled));
                }
            }
            Ok(Fitted {
                scale,
                lo: 10f64.powf(a),
                hi: 10f64.powf(b),
                ticks,
            })
        }
    }
}

/// Drops labels that would crowd: decades first, then the others, each kept only if it lies
/// at least `gap` pixels from every label kept (`pos` maps a value to its pixel).
fn thin_labels(ticks: &mut [(f64, bool)], pos: impl Fn(f64) -> f64, gap: f64) {
    let decade = |v: f64| {
        let l = v.abs().log10();
        (l - l.round()).abs() < 1e-9
    };
    let mut kept: Vec<f64> = Vec::new();
    for pass in [true, false] {
        for t in ticks.iter_mut() {
            if !t.1 || decade(t.0) != pass {
                continue;
            }
            let p = pos(t.0);
            if kept.iter().all(|k| (k - p).abs() >= gap) {
                kept.push(p);
            } else {
                t.1 = false;
            }
        }
    }
}

/// Where a plot's parts lie in the picture: its size, the plot area's corner and size, and
/// the fitted axes.
struct Layout {
    w: f64,
    h: f64,
    left: f64,
    top: f64,
    pw: f64,
    ph: f64,
    fx: Fitted,
    fy: Fitted,
}

impl Layout {
    /// The picture's `x` of the value `v`.
    fn px(&self, v: f64) -> f64 {
        self.left + self.fx.frac(v) * self.pw
    }

    /// The picture's `y` of the value `v`.
    fn py(&self, v: f64) -> f64 {
        self.top + (1.0 - self.fy.frac(v)) * self.ph
    }

    /// The grid lines, ticks and tick labels of both axes.
    fn write_ticks(&self, s: &mut String) {
        let (left, top, pw, ph) = (self.left, self.top, self.pw, self.ph);
        // Writing to a String cannot fail.
        let _ = writeln!(s, r#"<g class="x-ticks">"#);
        for &(v, labelled) in &self.fx.ticks {
            let x = self.px(v);
            let stroke = if labelled { "#ccc" } else { "#eee" };
            let _ = writeln!(
                s,
                r#"<line x1="{x:.1}" y1="{top:.1}" x2="{x:.1}" y2="{:.1}" stroke="{stroke}"/>"#,
                top + ph
            );
            let len = if labelled { 6.0 } else { 3.0 };
            let _ = writeln!(
                s,
                r#"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="black"/>"#,
                top + ph,
                top + ph + len
            );
            if labelled {
                let _ = writeln!(
                    s,
                    r#"<text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
                    top + ph + 20.0,
                    escape(&tick_text(v))
                );
            }
        }
        let _ = writeln!(s, "</g>");
        let _ = writeln!(s, r#"<g class="y-ticks">"#);
        for &(v, labelled) in &self.fy.ticks {
            let y = self.py(v);
            let stroke = if labelled { "#ccc" } else { "#eee" };
            let _ = writeln!(
                s,
                r#"<line x1="{left:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{stroke}"/>"#,
                left + pw
            );
            let len = if labelled { 6.0 } else { 3.0 };
            let _ = writeln!(
                s,
                r#"<line x1="{:.1}" y1="{y:.1}" x2="{left:.1}" y2="{y:.1}" stroke="black"/>"#,
                left - len
            );
            if labelled {
                let _ = writeln!(
                    s,
                    r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"#,
                    left - 9.0,
                    y + 4.0,
                    escape(&tick_text(v))
                );
            }
        }
        let _ = writeln!(s, "</g>");
    }

    /// The plot area's frame and the axes' titles.
    fn write_frame(&self, s: &mut String, x_label: &str, y_label: &str) {
        let (left, top, pw, ph) = (self.left, self.top, self.pw, self.ph);
        let _ = writeln!(
            s,
            r#"<rect x="{left:.1}" y="{top:.1}" width="{pw:.1}" height="{ph:.1}" fill="none" stroke="black"/>"#
        );
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle" font-size="13">{}</text>"#,
            left + pw / 2.0,
            self.h - 15.0,
            escape(x_label)
        );
        let _ = writeln!(
            s,
            r#"<text x="18" y="{:.1}" text-anchor="middle" font-size="13" transform="rotate(-90 18 {:.1})">{}</text>"#,
            top + ph / 2.0,
            top + ph / 2.0,
            escape(y_label)
        );
    }

    /// Series `k`: its line, its marked and labelled points, and its legend entry.
    fn write_series(&self, s: &mut String, k: usize, series: &Series) {
        let color = COLORS[k % COLORS.len()];
        let _ = writeln!(s, r#"<g class="series">"#);
        let line: Vec<String> = series
            .points
            .iter()
            .map(|&(x, y)| format!("{:.1},{:.1}", self.px(x), self.py(y)))
            .collect();
        let _ = writeln!(
            s,
            r#"<polyline points="{}" fill="none" stroke="{color}" stroke-width="1.5"/>"#,
            line.join(" ")
        );
        for (i, &(x, y)) in series.points.iter().enumerate() {
            let _ = writeln!(
                s,
                r#"<circle class="point" cx="{:.1}" cy="{:.1}" r="4" fill="{color}"/>"#,
                self.px(x),
                self.py(y)
            );
            if let Some(label) = series.labels.get(i).filter(|l| !l.is_empty()) {
                let _ = writeln!(
                    s,
                    r#"<text class="label" x="{:.1}" y="{:.1}">{}</text>"#,
                    self.px(x) + 7.0,
                    self.py(y) - 7.0,
                    escape(label)
                );
            }
        }
        let ly = self.top + 16.0 + 18.0 * k as f64;
        let lx = self.left + self.pw - 150.0;
        let _ = writeln!(
            s,
            r#"<line x1="{lx:.1}" y1="{ly:.1}" x2="{:.1}" y2="{ly:.1}" stroke="{color}" stroke-width="2"/>"#,
            lx + 20.0
        );
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}">{}</text>"#,
            lx + 26.0,
            ly + 4.0,
            escape(&series.name)
        );
        let _ = writeln!(s, "</g>");
    }
}

impl Plot {
    /// Fits the axes to the series and places the plot area.
    fn layout(&self) -> Result<Layout, Error> {
        let xs: Vec<f64> = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.0))
            .collect();
        let ys: Vec<f64> = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1))
            .collect();
        let mut fx = fit(&xs, self.x_scale, "x")?;
        let mut fy = fit(&ys, self.y_scale, "y")?;
        let (w, h) = (self.width.max(200) as f64, self.height.max(150) as f64);
        let (left, right, top, bottom) = (80.0, 30.0, 40.0, 60.0);
        let (pw, ph) = (w - left - right, h - top - bottom);
        let mut x_ticks = std::mem::take(&mut fx.ticks);
        thin_labels(&mut x_ticks, |v| fx.frac(v) * pw, 40.0);
        fx.ticks = x_ticks;
        let mut y_ticks = std::mem::take(&mut fy.ticks);
        thin_labels(&mut y_ticks, |v| fy.frac(v) * ph, 16.0);
        fy.ticks = y_ticks;
        Ok(Layout {
            w,
            h,
            left,
            top,
            pw,
            ph,
            fx,
            fy,
        })
    }

    /// The plot as an SVG document.
    pub fn to_svg(&self) -> Result<String, Error> {
        let layout = self.layout()?;
        let (w, h) = (layout.w, layout.h);
        let mut s = String::new();
        // Writing to a String cannot fail.
        let _ = writeln!(s, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
        let _ = writeln!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
        );
        let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="22" text-anchor="middle" font-size="15">{}</text>"#,
            layout.left + layout.pw / 2.0,
            escape(&self.title)
        );
        layout.write_ticks(&mut s);
        layout.write_frame(&mut s, &self.x_label, &self.y_label);
        for (k, series) in self.series.iter().enumerate() {
            layout.write_series(&mut s, k, series);
        }
        let _ = writeln!(s, "</svg>");
        Ok(s)
    }

    /// Writes the plot to an SVG file.
    pub fn write(&self, path: &Path) -> Result<(), Error> {
        let svg = self.to_svg()?;
        std::fs::write(path, svg).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_cover_the_data_with_decades() {
        let f = fit(&[2e-4, 3e-2], Scale::Log, "y").unwrap();
        assert!(f.lo < 2e-4 && f.hi > 3e-2);
        let labelled: Vec<f64> = f.ticks.iter().filter(|t| t.1).map(|t| t.0).collect();
        for d in [1e-3, 1e-2] {
            assert!(labelled.contains(&d), "{d} in {labelled:?}");
        }
        assert!(f.ticks.iter().all(|t| t.0 >= f.lo && t.0 <= f.hi));
    }

    #[test]
    fn narrow_log_range_still_gets_labels() {
        let f = fit(&[0.3, 0.5], Scale::Log, "x").unwrap();
        assert!(f.ticks.iter().filter(|t| t.1).count() >= 2);
    }

    #[test]
    fn crowded_labels_are_thinned_keeping_decades() {
        let mut ticks = vec![(0.09, true), (0.1, true), (0.2, true)];
        thin_labels(&mut ticks, |v| v * 100.0, 5.0);
        assert_eq!(ticks, vec![(0.09, false), (0.1, true), (0.2, true)]);
    }

    #[test]
    fn linear_ticks_are_round() {
        let f = fit(&[0.0, 7.3], Scale::Linear, "x").unwrap();
        assert!(f.ticks.len() >= 3);
        assert!(f.ticks.iter().any(|t| t.0 == 0.0));
    }

    #[test]
    fn bad_values_are_errors_and_text_is_escaped() {
        assert!(fit(&[0.0, 1.0], Scale::Log, "x").is_err());
        assert!(fit(&[f64::NAN], Scale::Linear, "x").is_err());
        assert_eq!(escape("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
        let plot = Plot {
            title: "<x>".into(),
            ..Plot::default()
        };
        assert!(plot.to_svg().unwrap().contains("&lt;x&gt;"));
    }

    #[test]
    fn a_series_of_labelled_points_on_log_axes() {
        let plot = Plot {
            title: "error against time".into(),
            x_label: "time (s)".into(),
            y_label: "rmse".into(),
            x_scale: Scale::Log,
            y_scale: Scale::Log,
            series: vec![Series {
                name: "cyl-bvh".into(),
                points: vec![(0.1, 1e-2), (0.2, 5e-3), (0.4, 2.4e-3)],
                labels: vec!["2×".into(), "1×".into(), "1/2×".into()],
            }],
            ..Plot::default()
        };
        let svg = plot.to_svg().unwrap();
        assert!(svg.starts_with("<?xml"));
        assert_eq!(svg.matches("class=\"point\"").count(), 3);
        assert_eq!(svg.matches("class=\"label\"").count(), 3);
    }

    #[test]
    fn tick_text_is_short() {
        assert_eq!(tick_text(0.002), "0.002");
        assert_eq!(tick_text(5.0), "5");
        assert_eq!(tick_text(1e-5), "1e-5");
    }
}
