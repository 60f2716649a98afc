//! The one figure stack: a file's backend chosen by its extension, written atomically, the font and the palette.

use std::path::Path as FsPath;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::{ReportError, Result};

/// The bitmap backend needs a font; the embedded DejaVu Sans avoids a system font lookup.
fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded font is a valid TTF; a failure would only lose text, never data.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// Draws to FILE with the backend its extension names (.svg or .png). The two closures
/// are the same drawing code, one per backend type.
pub fn to_file(
    file: &FsPath,
    size: (u32, u32),
    svg: impl FnOnce(DrawingArea<SVGBackend, Shift>) -> Result<()>,
    png: impl FnOnce(DrawingArea<BitMapBackend, Shift>) -> Result<()>,
) -> Result<()> {
    register_font();
    let ext = file
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("svg" | "png")) {
        return Err(ReportError::File {
            file: file.to_path_buf(),
            reason: "plot file must end in .svg or .png".into(),
        });
    }
    if std::fs::symlink_metadata(file).is_ok_and(|m| !m.is_file()) {
        return Err(ReportError::File {
            file: file.to_path_buf(),
            reason: "exists and is not a regular file; give a file's path for the plot".into(),
        });
    }
    // Drawn to a temporary file beside the target and presented explicitly (plotters
    // only logs a failed write when a backend is dropped), then renamed over it: a full
    // disk or a missing folder is an error naming the file, never a truncated plot.
    // Beside the target, keeping its extension (the backend picks the format by it).
    let name = file
        .file_name()
        .map_or_else(|| "plot".into(), |n| n.to_string_lossy());
    let tmp = file.with_file_name(format!(".tmp-{}-{name}", std::process::id()));
    let result = if ext.as_deref() == Some("svg") {
        let area = SVGBackend::new(&tmp, size).into_drawing_area();
        svg(area.clone()).and_then(|()| {
            area.present()
                .map_err(|e| ReportError::Backend(e.to_string()))
        })
    } else {
        let area = BitMapBackend::new(&tmp, size).into_drawing_area();
        png(area.clone()).and_then(|()| {
            area.present()
                .map_err(|e| ReportError::Backend(e.to_string()))
        })
    };
    let result = result.and_then(|()| {
        std::fs::File::open(&tmp)
            .and_then(|f| f.sync_all())
            .and_then(|()| std::fs::rename(&tmp, file))
            .map_err(|e| ReportError::Backend(e.to_string()))
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(|e| ReportError::Drawing {
        file: file.to_path_buf(),
        reason: e.to_string(),
    })
}

/// A plotting backend's error as the crate's.
pub fn err<E: std::fmt::Debug>(e: E) -> ReportError {
    ReportError::Backend(format!("{e:?}"))
}

/// The figures' series colours: [`crate::TAB10`] without its grey and olive.
pub const COLORS: [RGBColor; 8] = {
    const fn rgb(i: usize) -> RGBColor {
        let (r, g, b) = crate::TAB10[i];
        RGBColor(r, g, b)
    }
    [
        rgb(0),
        rgb(1),
        rgb(2),
        rgb(3),
        rgb(4),
        rgb(5),
        rgb(6),
        rgb(9),
    ]
};

/// The colour of series `i` of `n`: the palette's up to its size, else evenly spaced
/// hues, so no two series share one.
pub fn series_colour(i: usize, n: usize) -> RGBColor {
    if n <= COLORS.len() {
        return COLORS[i % COLORS.len()];
    }
    let c = HSLColor(i as f64 / n as f64, 0.7, 0.42).to_rgba();
    RGBColor(c.0, c.1, c.2)
}
