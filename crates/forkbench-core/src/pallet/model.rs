//! A pallet kind as built (blocks, notches, entry faces) and the pallet it is from each face.

use serde::{Deserialize, Serialize};

use super::{PalletBlock, PalletSpec, channels};
use crate::SettingsError;

/// A side of the pallet, in the frame its blocks are given in: `front` is the face at
/// x = 0, `left` the side at +y.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PalletFace {
    Front,
    Back,
    Left,
    Right,
}

impl PalletFace {
    pub fn name(self) -> &'static str {
        match self {
            Self::Front => "front",
            Self::Back => "back",
            Self::Left => "left",
            Self::Right => "right",
        }
    }

    /// Whether this face is one of the sides the stringers run along.
    fn is_side(self) -> bool {
        matches!(self, Self::Left | Self::Right)
    }
}

/// A notch cut from below into every part it crosses, across the whole width: the
/// openings that make a stringer pallet four-way (partially: only forks thinner than the
/// notch fit).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PalletNotch {
    /// Centre, from the front face.
    pub x_m: f64,
    /// Extent along the depth.
    pub length_m: f64,
    /// How high the cut reaches: the opening's height.
    pub height_m: f64,
}

/// A pallet kind: its footprint and parts as seen from the front, which faces a fork may
/// enter, and the pocket heights. Built-in kinds: [`PalletModel::builtin`]; a custom one
/// is the `[pallet_model]` table of a scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PalletModel {
    pub name: String,
    /// Extent from the front face to the back.
    pub depth_m: f64,
    /// Extent across the front face.
    pub width_m: f64,
    pub mass_kg: f64,
    /// Opening height of the pockets between the parts (deck to deck, or deck to floor).
    pub pocket_height_m: f64,
    /// The parts where the scan plane cuts them at the front pockets' height.
    #[serde(rename = "block")]
    pub blocks: Vec<PalletBlock>,
    /// Notches cut into the parts from below (opening the left and right faces).
    #[serde(default, rename = "notch")]
    pub notches: Vec<PalletNotch>,
    /// The faces a fork may enter.
    pub entry: Vec<PalletFace>,
}

fn field(name: &str, reason: impl Into<String>) -> SettingsError {
    SettingsError::field(name, reason)
}

impl PalletModel {
    /// The pallet met from `face`, its parts turned so that face is at x = 0. Refused
    /// when the kind does not allow entry there, or its parts leave not exactly two
    /// mirror-image pockets through the whole depth behind that face.
    pub fn entered_from(&self, face: PalletFace) -> Result<PalletSpec, SettingsError> {
        self.validate()?;
        if !self.entry.contains(&face) {
            let allowed: Vec<&str> = self.entry.iter().map(|f| f.name()).collect();
            return Err(field(
                "pallet_entry",
                format!(
                    "{} does not allow entry from its {} face (entry faces: {})",
                    self.name,
                    face.name(),
                    allowed.join(", ")
                ),
            ));
        }
        // The parts in one order whatever the file's: contacts and scans are resolved in
        // the colliders' order, so a reordered table would otherwise change outcomes.
        // Across, then along (the order the built-in kinds are written in).
        let mut canonical = self.clone();
        canonical.blocks.sort_by(|a, b| {
            (a.y_m.total_cmp(&b.y_m))
                .then(a.x_m.total_cmp(&b.x_m))
                .then(a.length_m.total_cmp(&b.length_m))
                .then(a.width_m.total_cmp(&b.width_m))
        });
        let (blocks, pocket_height_m) = canonical.cut_for(face);
        let (depth_m, width_m) = match face {
            PalletFace::Front | PalletFace::Back => (self.depth_m, self.width_m),
            PalletFace::Left | PalletFace::Right => (self.width_m, self.depth_m),
        };
        let blocks: Vec<PalletBlock> = blocks
            .iter()
            .map(|b| turn(b, face, self.depth_m, self.width_m))
            .collect();
        let pocket_width_m = check_pockets(&self.name, face, &blocks, width_m)?;
        Ok(PalletSpec {
            depth_m,
            width_m,
            pocket_width_m,
            mass_kg: self.mass_kg,
            payload_kg: 0.0,
            blocks,
            pocket_height_m: Some(pocket_height_m),
        })
    }

    /// The parts a scan plane cuts when entering from `face`, and the pocket height there:
    /// through the notches from a notched side.
    fn cut_for(&self, face: PalletFace) -> (Vec<PalletBlock>, f64) {
        if face.is_side() && !self.notches.is_empty() {
            let h = self
                .notches
                .iter()
                .map(|n| n.height_m)
                .fold(f64::INFINITY, f64::min);
            (self.notched_blocks(), h)
        } else {
            (self.blocks.clone(), self.pocket_height_m)
        }
    }

    /// The parts with every notch cut out of them: what a scan plane through the notches
    /// cuts.
    fn notched_blocks(&self) -> Vec<PalletBlock> {
        let mut out = Vec::new();
        for b in &self.blocks {
            let mut pieces = vec![b.x_range()];
            for n in &self.notches {
                let (lo, hi) = (n.x_m - n.length_m / 2.0, n.x_m + n.length_m / 2.0);
                pieces = pieces
                    .into_iter()
                    .flat_map(|[a, z]| {
                        if hi <= a || lo >= z {
                            vec![[a, z]]
                        } else {
                            [[a, lo], [hi, z]]
                                .into_iter()
                                .filter(|[p, q]| q - p > 1e-9)
                                .collect()
                        }
                    })
                    .collect();
            }
            out.extend(pieces.into_iter().map(|[a, z]| PalletBlock {
                x_m: (a + z) / 2.0,
                length_m: z - a,
                ..*b
            }));
        }
        out
    }

    /// Values, parts inside the footprint and not overlapping, notches within the depth.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let mut ranges = vec![
            ("depth_m", self.depth_m, 0.1, 5.0),
            ("width_m", self.width_m, 0.1, 5.0),
            ("mass_kg", self.mass_kg, 0.1, 10_000.0),
            ("pocket_height_m", self.pocket_height_m, 0.01, 1.0),
        ];
        for n in &self.notches {
            ranges.push(("notch.length_m", n.length_m, 0.01, self.depth_m));
            ranges.push(("notch.height_m", n.height_m, 0.005, 1.0));
            ranges.push(("notch.x_m", n.x_m, 0.0, self.depth_m));
        }
        crate::settings::in_ranges(&ranges)?;
        if self.blocks.is_empty() || self.blocks.len() > 64 {
            return Err(field(
                "block",
                format!("needs 1–64 parts (got {})", self.blocks.len()),
            ));
        }
        if self.notches.len() > 16 {
            return Err(field(
                "notch",
                format!("at most 16 notches (got {})", self.notches.len()),
            ));
        }
        if self.entry.is_empty() {
            return Err(field("entry", "names no face a fork may enter"));
        }
        for (i, b) in self.blocks.iter().enumerate() {
            let at = format!("block[{i}]");
            crate::settings::in_ranges(&[
                ("length_m", b.length_m, 0.005, self.depth_m),
                ("width_m", b.width_m, 0.005, self.width_m),
            ])
            .map_err(|e| field(&format!("{at}.{}", e.field.unwrap_or_default()), e.reason))?;
            let ([x0, x1], [y0, y1]) = (b.x_range(), b.y_range());
            let (hd, hw) = (self.depth_m, self.width_m / 2.0);
            if !(x0 >= -1e-9 && x1 <= hd + 1e-9 && y0 >= -hw - 1e-9 && y1 <= hw + 1e-9) {
                return Err(field(
                    &at,
                    format!(
                        "reaches outside the {} × {} m footprint (x {x0:.4}..{x1:.4} m from the front face, y {y0:.4}..{y1:.4} m)",
                        self.depth_m, self.width_m
                    ),
                ));
            }
            if let Some(j) = self.blocks[..i].iter().position(|o| overlap(o, b)) {
                return Err(field(&at, format!("overlaps block[{j}]")));
            }
        }
        Ok(())
    }
}

fn overlap(a: &PalletBlock, b: &PalletBlock) -> bool {
    let ([ax0, ax1], [ay0, ay1]) = (a.x_range(), a.y_range());
    let ([bx0, bx1], [by0, by1]) = (b.x_range(), b.y_range());
    ax0 < bx1 - 1e-9 && bx0 < ax1 - 1e-9 && ay0 < by1 - 1e-9 && by0 < ay1 - 1e-9
}

/// `b` (given from the front) in the frame of a truck entering `face`: that face at
/// x = 0, x into the pallet, y to the truck's left.
fn turn(b: &PalletBlock, face: PalletFace, depth_m: f64, width_m: f64) -> PalletBlock {
    let (x, y) = (b.x_m, b.y_m);
    let (h, w) = (depth_m / 2.0, width_m / 2.0);
    match face {
        PalletFace::Front => *b,
        PalletFace::Back => PalletBlock {
            x_m: depth_m - x,
            y_m: -y,
            ..*b
        },
        // From the left side (+y), heading −y: into the pallet is −y, the truck's left +x.
        PalletFace::Left => PalletBlock {
            x_m: w - y,
            y_m: x - h,
            length_m: b.width_m,
            width_m: b.length_m,
        },
        PalletFace::Right => PalletBlock {
            x_m: w + y,
            y_m: h - x,
            length_m: b.width_m,
            width_m: b.length_m,
        },
    }
}

/// The common width of the two pockets behind the face: exactly two gaps that run the
/// whole depth, mirror images about the axis, with material at both edges and in the
/// middle of the face.
fn check_pockets(
    name: &str,
    face: PalletFace,
    blocks: &[PalletBlock],
    width_m: f64,
) -> Result<f64, SettingsError> {
    let gaps = channels(blocks, width_m);
    let at = format!("{name} entered from its {} face", face.name());
    let [[r0, r1], [l0, l1]] = gaps[..] else {
        return Err(field(
            "block",
            format!(
                "{at}: the parts leave {} gaps through the whole depth; a truck's two forks need exactly two pockets",
                gaps.len()
            ),
        ));
    };
    if (r0 + l1).abs() > 1e-3 || (r1 + l0).abs() > 1e-3 {
        return Err(field(
            "block",
            format!(
                "{at}: the pockets ({r0:.4}..{r1:.4} m and {l0:.4}..{l1:.4} m) are not mirror images about the axis, as the forks are"
            ),
        ));
    }
    let h = width_m / 2.0;
    if r0 <= -h + 1e-6 || l1 >= h - 1e-6 || r1 >= -1e-6 || l0 <= 1e-6 {
        return Err(field(
            "block",
            format!("{at}: a pocket is open at the pallet's edge or across its axis"),
        ));
    }
    // What the scanner sees of the face: each solid interval covered by parts at x = 0.
    let front: Vec<[f64; 2]> = blocks
        .iter()
        .filter(|b| b.x_range()[0].abs() < 1e-6)
        .map(PalletBlock::y_range)
        .collect();
    for [lo, hi] in [[-h, r0], [r1, l0], [l1, h]] {
        let covered: f64 = front
            .iter()
            .map(|[a, b]| (b.min(hi) - a.max(lo)).max(0.0))
            .sum();
        if covered < (hi - lo) - 1e-6 {
            return Err(field(
                "block",
                format!(
                    "{at}: the face from {lo:.4} to {hi:.4} m across has no part at its front; the face a detector sees must be solid between the pockets"
                ),
            ));
        }
    }
    Ok(l1 - l0)
}
