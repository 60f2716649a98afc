//! ROS map_server maps: a YAML file (resolution, origin, thresholds) beside a PGM image, read and written.
//!
//! The PGM is read here rather than through the `image` crate: rerun builds `image` with
//! other features, and asking for PNM would rebuild rerun (about 10 minutes) for a format
//! that is a short header and raw bytes.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::grid::{Cell, GridError, OccupancyGrid};

/// A map that could not be read or written; every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum MapError {
    #[error("{path}: {message}")]
    Io { path: String, message: String },
    #[error("{path}: {message}")]
    Yaml { path: String, message: String },
    #[error("{path}: field `{field}`: {reason}")]
    Field {
        path: String,
        field: &'static str,
        reason: String,
    },
    #[error("{path}: not a PGM image this reader knows: {reason}")]
    Image { path: String, reason: PgmError },
    #[error("{path}: {source}")]
    Grid { path: String, source: GridError },
    /// Not a regular file, too large, or an I/O error; names the file, never its contents.
    #[error(transparent)]
    File(#[from] forkbench_core::files::FileError),
}

/// The map's YAML, as map_server reads it (unknown fields are allowed: Nav2 adds some).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapYaml {
    pub image: String,
    pub resolution: f64,
    /// Lower-left corner of the image's bottom-left pixel: x, y, yaw (ignored, as ROS does).
    pub origin: [f64; 3],
    #[serde(default)]
    pub negate: u8,
    pub occupied_thresh: f64,
    pub free_thresh: f64,
    #[serde(default = "trinary")]
    pub mode: String,
}

fn trinary() -> String {
    "trinary".to_owned()
}

/// Grey levels map_server's saver writes for each state.
const FREE_GREY: u8 = 254;
const OCCUPIED_GREY: u8 = 0;
const UNKNOWN_GREY: u8 = 205;

/// Writes `grid` as `dir/name.yaml` and `dir/name.pgm`; returns the YAML's path.
pub fn write_map(grid: &OccupancyGrid, dir: &Path, name: &str) -> Result<PathBuf, MapError> {
    let yaml_path = dir.join(format!("{name}.yaml"));
    let pgm_path = dir.join(format!("{name}.pgm"));
    let meta = MapYaml {
        image: format!("{name}.pgm"),
        resolution: grid.resolution_m,
        origin: [grid.origin_m[0], grid.origin_m[1], 0.0],
        negate: 0,
        // ROS map_saver's thresholds: with 0.196 its unknown grey (205) reads back unknown.
        occupied_thresh: 0.65,
        free_thresh: 0.196,
        mode: trinary(),
    };
    let mut pgm = format!(
        "P5\n# forkbench occupancy grid, {} m per cell\n{} {}\n255\n",
        grid.resolution_m, grid.width, grid.height
    )
    .into_bytes();
    // PGM rows go from the top of the image: the highest y first.
    for iy in (0..grid.height).rev() {
        pgm.extend((0..grid.width).map(|ix| match grid.get(ix, iy) {
            Cell::Free => FREE_GREY,
            Cell::Occupied => OCCUPIED_GREY,
            Cell::Unknown => UNKNOWN_GREY,
        }));
    }
    forkbench_core::files::write_atomic(&pgm_path, &pgm)?;
    let yaml = serde_norway::to_string(&meta).map_err(|e| MapError::Yaml {
        path: yaml_path.display().to_string(),
        message: e.to_string(),
    })?;
    forkbench_core::files::write_atomic(&yaml_path, yaml.as_bytes())?;
    Ok(yaml_path)
}

/// A parser's message with every quoted string replaced by `"…"`: the path may name any
/// file (a map YAML that is really something else), and its contents stay out of messages.
fn redact_quoted(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let mut inside = false;
    for c in message.chars() {
        match (c, inside) {
            ('"', false) => {
                out.push_str("\"…\"");
                inside = true;
            }
            ('"', true) => inside = false,
            (c, false) => out.push(c),
            (_, true) => {}
        }
    }
    out
}

/// Deepest nesting a map YAML may have, in brackets or in indentation: map_server's file
/// is flat, and a YAML parser's time grows with the square of the depth.
pub const MAX_YAML_DEPTH: usize = 32;

/// Why `text` nests too deeply to be a map's YAML, if it does: flow brackets or
/// indentation deeper than [`MAX_YAML_DEPTH`] levels.
fn too_deep(text: &str) -> Option<String> {
    for (n, line) in text.lines().enumerate() {
        let indent = line.len() - line.trim_start_matches([' ', '\t']).len();
        if indent > 4 * MAX_YAML_DEPTH {
            return Some(format!(
                "line {}: indented {indent} columns, deeper than a map's YAML ever is (at most {})",
                n + 1,
                4 * MAX_YAML_DEPTH
            ));
        }
    }
    // Every bracket counts, quoted or not: a quote a parser would not honour must not
    // hide a nest from this check, and a flat map never has 32 brackets open.
    let (mut depth, mut line) = (0usize, 1usize);
    for c in text.chars() {
        match c {
            '\n' => line += 1,
            '[' | '{' => {
                depth += 1;
                if depth > MAX_YAML_DEPTH {
                    return Some(format!(
                        "line {line}: brackets nest deeper than {MAX_YAML_DEPTH} levels; a map's YAML is flat"
                    ));
                }
            }
            ']' | '}' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    None
}

/// Largest map YAML read.
pub const MAX_YAML_BYTES: u64 = 1 << 20;

/// Largest PGM image read: 16,384 × 16,384 cells (820 × 820 m at 5 cm).
pub const MAX_IMAGE_BYTES: u64 = 256 << 20;

/// Reads a map_server map: the YAML at `path` and the PGM it names (relative to the YAML).
pub fn read_map(path: &Path) -> Result<OccupancyGrid, MapError> {
    let p = path.display().to_string();
    let text = forkbench_core::files::read_text(path, MAX_YAML_BYTES)?;
    if let Some(reason) = too_deep(&text) {
        return Err(MapError::Yaml {
            path: p,
            message: reason,
        });
    }
    let meta: MapYaml = serde_norway::from_str(&text).map_err(|e| MapError::Yaml {
        path: p.clone(),
        message: redact_quoted(&e.to_string()),
    })?;
    check(&meta, &p)?;
    let image = path.parent().unwrap_or(Path::new(".")).join(&meta.image);
    let bytes = forkbench_core::files::read_bytes(&image, MAX_IMAGE_BYTES)?;
    let pgm = parse_pgm(&bytes).map_err(|reason| MapError::Image {
        path: image.display().to_string(),
        reason,
    })?;
    let origin = [meta.origin[0], meta.origin[1]];
    let mut grid = OccupancyGrid::new(
        meta.resolution,
        origin,
        (pgm.width, pgm.height),
        Cell::Unknown,
    )
    .map_err(|source| MapError::Grid { path: p, source })?;
    for row in 0..pgm.height {
        for ix in 0..pgm.width {
            let v = f64::from(pgm.pixels[row * pgm.width + ix]) / f64::from(pgm.max);
            // map_server: occupancy probability from the grey level, then the thresholds.
            let occ = if meta.negate == 0 { 1.0 - v } else { v };
            let cell = if occ > meta.occupied_thresh {
                Cell::Occupied
            } else if occ < meta.free_thresh {
                Cell::Free
            } else {
                Cell::Unknown
            };
            grid.set(ix, pgm.height - 1 - row, cell);
        }
    }
    Ok(grid)
}

/// The YAML's numbers, checked before the image is read.
fn check(m: &MapYaml, path: &str) -> Result<(), MapError> {
    let field = |field, reason: &str| MapError::Field {
        path: path.to_owned(),
        field,
        reason: reason.to_owned(),
    };
    if !(m.resolution.is_finite() && m.resolution > 0.0) {
        return Err(field(
            "resolution",
            "must be a positive number of metres per cell",
        ));
    }
    if !m.origin.iter().all(|v| v.is_finite()) {
        return Err(field("origin", "must be three finite numbers [x, y, yaw]"));
    }
    if !(0.0..=1.0).contains(&m.free_thresh)
        || !(0.0..=1.0).contains(&m.occupied_thresh)
        || m.free_thresh > m.occupied_thresh
    {
        return Err(field(
            "free_thresh",
            "thresholds must satisfy 0 ≤ free_thresh ≤ occupied_thresh ≤ 1",
        ));
    }
    if m.negate > 1 {
        return Err(field("negate", "must be 0 or 1"));
    }
    if m.mode != "trinary" && m.mode != "scale" {
        return Err(field(
            "mode",
            "must be trinary or scale (raw maps are not read)",
        ));
    }
    Ok(())
}

/// Why an image is not a PGM this reader knows; never quotes the file's bytes (the path
/// may be any file).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PgmError {
    #[error("the header ends early")]
    HeaderEnds,
    #[error("it does not start with P5 (a binary greyscale PGM)")]
    NotP5,
    #[error("its {0} is not a whole number")]
    NotNumber(&'static str),
    #[error("{width} × {height} pixels, maxval {max}: expected a non-empty 8-bit image")]
    Shape {
        width: usize,
        height: usize,
        max: usize,
    },
    #[error("the image is too large")]
    TooLarge,
    #[error("{got} pixel bytes, expected {need}")]
    Pixels { got: usize, need: usize },
}

/// A greyscale image.
struct Pgm {
    width: usize,
    height: usize,
    max: u16,
    pixels: Vec<u8>,
}

/// Parses a binary (P5) 8-bit PGM, comments allowed in the header.
fn parse_pgm(bytes: &[u8]) -> Result<Pgm, PgmError> {
    let mut pos = 0;
    let mut token = || -> Result<String, PgmError> {
        loop {
            while pos < bytes.len() && bytes[pos].is_ascii_whitespace() {
                pos += 1;
            }
            if pos < bytes.len() && bytes[pos] == b'#' {
                while pos < bytes.len() && bytes[pos] != b'\n' {
                    pos += 1;
                }
                continue;
            }
            let start = pos;
            while pos < bytes.len() && !bytes[pos].is_ascii_whitespace() {
                pos += 1;
            }
            if start == pos {
                return Err(PgmError::HeaderEnds);
            }
            return Ok(String::from_utf8_lossy(&bytes[start..pos]).into_owned());
        }
    };
    if token()? != "P5" {
        return Err(PgmError::NotP5);
    }
    let mut number = |what: &'static str| -> Result<usize, PgmError> {
        token()?
            .parse::<usize>()
            .map_err(|_| PgmError::NotNumber(what))
    };
    let (width, height, max) = (number("width")?, number("height")?, number("maxval")?);
    if width == 0 || height == 0 || !(1..=255).contains(&max) {
        return Err(PgmError::Shape { width, height, max });
    }
    // One whitespace byte separates the header from the pixels.
    let start = pos + 1;
    let need = width.checked_mul(height).ok_or(PgmError::TooLarge)?;
    let end = start.checked_add(need).ok_or(PgmError::TooLarge)?;
    let pixels = bytes.get(start..end).ok_or(PgmError::Pixels {
        got: bytes.len().saturating_sub(start),
        need,
    })?;
    Ok(Pgm {
        width,
        height,
        max: max as u16,
        pixels: pixels.to_vec(),
    })
}
