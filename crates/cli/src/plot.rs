//! Quality histograms drawn with plotters: dihedral angles and radius
//! ratio side by side, optionally over the histograms of an earlier mesh
//! (before improvement). SVG when the path ends in `.svg`, else PNG. The
//! font is embedded, so no system font is needed.
// Until main.rs calls plot_histograms, the binary build sees it unused.

use parafront_mesh::quality::{Histogram, QualityReport};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// DejaVu Sans (Bitstream Vera licence, see assets/DejaVuSans-LICENSE.txt).
const FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

const SIZE: (u32, u32) = (1400, 560);
const AFTER: RGBColor = RGBColor(31, 119, 180);
const BEFORE: RGBColor = RGBColor(214, 39, 40);

#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    #[error("the embedded plot font could not be loaded")]
    Font,
    #[error("cannot draw the histogram plot {path}: {msg}")]
    Draw { path: PathBuf, msg: String },
    #[error("cannot write the histogram plot {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

fn register_font() -> Result<(), PlotError> {
    static OK: OnceLock<bool> = OnceLock::new();
    let ok = *OK.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).is_ok()
    });
    ok.then_some(()).ok_or(PlotError::Font)
}

/// Draws the dihedral-angle histogram (all six angles of every tet) and
/// the radius-ratio histogram of `report`, with `before` outlined behind
/// them when given, into `path`. Writes a temporary file beside `path`
/// and renames it, so a failed run leaves no half-written plot.
pub fn plot_histograms(
    report: &QualityReport,
    before: Option<&QualityReport>,
    path: &Path,
) -> Result<(), PlotError> {
    register_font()?;
    let io_err = |source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    };
    let draw_err = |msg: String| PlotError::Draw {
        path: path.to_path_buf(),
        msg,
    };
    let svg = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"));
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let stem = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "plot".into());
    // The bitmap backend picks its encoder from the extension: keep `.png`.
    let tmp = dir.join(format!(
        ".{stem}.tmp-{}.{}",
        std::process::id(),
        if svg { "svg" } else { "png" }
    ));
    let result = (|| {
        if svg {
            let mut s = String::new();
            {
                let root = SVGBackend::with_string(&mut s, SIZE).into_drawing_area();
                draw(&root, report, before).map_err(draw_err)?;
                root.present().map_err(|e| draw_err(e.to_string()))?;
            }
            std::fs::write(&tmp, s).map_err(io_err)
        } else {
            let root = BitMapBackend::new(&tmp, SIZE).into_drawing_area();
            draw(&root, report, before).map_err(draw_err)?;
            root.present().map_err(|e| draw_err(e.to_string()))
        }
    })();
    let result = result.and_then(|()| std::fs::rename(&tmp, path).map_err(io_err));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    report: &QualityReport,
    before: Option<&QualityReport>,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let (left, right) = root.split_horizontally(SIZE.0 / 2);
    panel(
        &left,
        &format!("Dihedral angles ({} tets)", report.n_tets),
        "dihedral angle (degrees)",
        "share of angles (%)",
        &report.dihedral_hist,
        before.map(|b| &b.dihedral_hist),
        (0.0, 180.0),
        0,
    )?;
    panel(
        &right,
        &format!(
            "Radius ratio (min {:.3}, mean {:.3})",
            report.radius_ratio.min, report.radius_ratio.mean
        ),
        "radius ratio 3r/R",
        "share of tets (%)",
        &report.radius_ratio_hist,
        before.map(|b| &b.radius_ratio_hist),
        (0.0, 1.0),
        1,
    )
}

/// Percent per bin.
fn shares(h: &Histogram) -> Vec<f64> {
    let n = h.total().max(1) as f64;
    h.counts.iter().map(|&c| 100.0 * c as f64 / n).collect()
}

#[allow(clippy::too_many_arguments)]
fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    xdesc: &str,
    ydesc: &str,
    h: &Histogram,
    before: Option<&Histogram>,
    xr: (f64, f64),
    xprec: usize,
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let now = shares(h);
    let old = before.map(shares);
    let ymax = now
        .iter()
        .chain(old.iter().flatten())
        .copied()
        .fold(0.0, f64::max)
        .max(1e-3)
        * 1.1;
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 24))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(64)
        .build_cartesian_2d(xr.0..xr.1, 0.0..ymax)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(xdesc)
        .y_desc(ydesc)
        .axis_desc_style(("sans-serif", 18))
        .label_style(("sans-serif", 14))
        .disable_x_mesh()
        .x_labels(10)
        .x_label_formatter(&|x| format!("{x:.xprec$}"))
        .y_label_formatter(&|y| format!("{y:.0}"))
        .draw()
        .map_err(e)?;
    let bars = |v: &[f64], hist: &Histogram| -> Vec<(f64, f64, f64)> {
        v.iter()
            .enumerate()
            .filter(|(_, &y)| y > 0.0)
            .map(|(i, &y)| (hist.bin_lo(i), hist.bin_lo(i + 1), y))
            .collect()
    };
    if let (Some(old), Some(bh)) = (&old, before) {
        chart
            .draw_series(
                bars(old, bh)
                    .into_iter()
                    .map(|(a, b, y)| Rectangle::new([(a, 0.0), (b, y)], BEFORE.mix(0.35).filled())),
            )
            .map_err(e)?
            .label("before")
            .legend(|(x, y)| {
                Rectangle::new([(x, y - 6), (x + 14, y + 6)], BEFORE.mix(0.35).filled())
            });
    }
    chart
        .draw_series(
            bars(&now, h)
                .into_iter()
                .map(|(a, b, y)| Rectangle::new([(a, 0.0), (b, y)], AFTER.mix(0.75).filled())),
        )
        .map_err(e)?
        .label(if old.is_some() { "after" } else { "mesh" })
        .legend(|(x, y)| Rectangle::new([(x, y - 6), (x + 14, y + 6)], AFTER.mix(0.75).filled()));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 16))
        .draw()
        .map_err(e)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use parafront_mesh::generate::box_mesh;

    #[test]
    fn draws_png_and_svg() {
        let dir = std::env::temp_dir().join(format!("parafront-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut m = box_mesh(3, 3, 3, [0.0; 3], [1.0; 3]);
        let before = QualityReport::new(&m);
        // Move an interior point: a different histogram to overlay.
        m.points[21] = [0.4, 0.3, 0.35];
        let after = QualityReport::new(&m);
        assert_ne!(before.dihedral_hist, after.dihedral_hist);

        let png = dir.join("q.png");
        plot_histograms(&after, Some(&before), &png).unwrap();
        let bytes = std::fs::read(&png).unwrap();
        assert!(bytes.len() > 1000);
        assert_eq!(&bytes[1..4], b"PNG");

        let svg = dir.join("q.svg");
        plot_histograms(&after, None, &svg).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        for t in [
            "dihedral angle (degrees)",
            "radius ratio 3r/R",
            "share of tets (%)",
            "<rect",
        ] {
            assert!(text.contains(t), "{t} not in the SVG");
        }
        // No temporary files left behind.
        let left: Vec<_> = std::fs::read_dir(&dir).unwrap().flatten().collect();
        assert_eq!(left.len(), 2);

        // An unwritable place is an error naming the path, not a panic.
        let bad = dir.join("no/such/dir/q.svg");
        let err = plot_histograms(&after, None, &bad).unwrap_err();
        assert!(err.to_string().contains("no/such/dir"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
