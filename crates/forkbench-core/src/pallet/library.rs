//! The built-in pallet kinds: EUR/EPAL 1, ISO 1200 × 1000 and GMA 48 × 40, with their sources.

use super::{PalletBlock, PalletFace, PalletModel, PalletNotch};

const ALL_FACES: [PalletFace; 4] = [
    PalletFace::Front,
    PalletFace::Back,
    PalletFace::Left,
    PalletFace::Right,
];

const INCH_M: f64 = 0.0254;

/// A 3 × 3 grid of blocks: `rows` are (lateral centre, width) across the front face,
/// `cols` (centre from the front, length) along the depth.
fn block_grid(rows: [(f64, f64); 3], cols: [(f64, f64); 3]) -> Vec<PalletBlock> {
    rows.iter()
        .flat_map(|&(y_m, width_m)| {
            cols.iter().map(move |&(x_m, length_m)| PalletBlock {
                x_m,
                y_m,
                length_m,
                width_m,
            })
        })
        .collect()
}

/// How a built-in kind is made: the papers' two-way stringer pallets as a plain spec, the
/// standards' pallets as a model of parts entered from a face.
#[derive(Debug, Clone, Copy)]
pub enum PalletBuild {
    Stringers(fn() -> super::PalletSpec),
    Parts(fn() -> PalletModel),
}

/// One built-in pallet kind: its name in scenario files, what it is, how it is made.
#[derive(Debug, Clone, Copy)]
pub struct PalletKind {
    pub name: &'static str,
    pub describe: &'static str,
    pub build: PalletBuild,
}

/// Every built-in pallet kind, once: a scenario's `pallet_kind` names one of these.
/// Adding a kind is a row here.
pub const PALLET_KINDS: &[PalletKind] = &[
    PalletKind {
        name: "field-1200",
        describe: "1.2 × 1.2 m, 0.405 m pockets, two-way stringers (the field test)",
        build: PalletBuild::Stringers(super::PalletSpec::field_1200),
    },
    PalletKind {
        name: "sim-1000",
        describe: "1.0 × 1.0 m, 0.35 m pockets, two-way stringers (the papers' simulations)",
        build: PalletBuild::Stringers(super::PalletSpec::sim_1000),
    },
    PalletKind {
        name: "epal-1",
        describe: "EUR/EPAL 1, 1200 × 800 mm, nine blocks, four-way",
        build: PalletBuild::Parts(PalletModel::epal_1),
    },
    PalletKind {
        name: "iso-1200x1000",
        describe: "ISO 1200 × 1000 mm, nine blocks, four-way",
        build: PalletBuild::Parts(PalletModel::iso_1200x1000),
    },
    PalletKind {
        name: "gma-48x40",
        describe: "GMA 48 × 40 in, three notched stringers, partial four-way",
        build: PalletBuild::Parts(PalletModel::gma_48x40),
    },
];

impl PalletKind {
    /// The built-in kind `name`; refused with the known names.
    pub fn by_name(name: &str) -> Result<&'static PalletKind, crate::UnknownChoice> {
        PALLET_KINDS.iter().find(|k| k.name == name).ok_or_else(|| {
            let known: Vec<_> = PALLET_KINDS.iter().map(|k| k.name).collect();
            crate::UnknownChoice::new(
                name,
                format!("no such pallet kind (known: {})", known.join(", ")),
            )
        })
    }
}

impl PalletModel {
    /// A built-in kind made of parts, by name (a stringer kind has no parts model).
    pub fn builtin(name: &str) -> Option<Self> {
        match PalletKind::by_name(name).ok()?.build {
            PalletBuild::Parts(model) => Some(model()),
            PalletBuild::Stringers(_) => None,
        }
    }

    /// The names of the built-in kinds made of parts, in the table's order.
    pub fn builtin_names() -> impl Iterator<Item = &'static str> {
        PALLET_KINDS
            .iter()
            .filter(|k| matches!(k.build, PalletBuild::Parts(_)))
            .map(|k| k.name)
    }

    /// EUR/EPAL 1 (EN 13698-1): 1200 × 800 mm, nine blocks, four-way. The front is the
    /// 800 mm face; its outer blocks are 100 mm wide and the middle row 145 mm, every block
    /// 145 mm along the 1200 mm side, which leaves the standard's openings: 227.5 mm on
    /// the 800 mm faces and 382.5 mm on the 1200 mm faces, 100 mm high.
    pub fn epal_1() -> Self {
        let cols = [(0.0725, 0.145), (0.6, 0.145), (1.1275, 0.145)];
        Self {
            name: "epal-1".into(),
            depth_m: 1.2,
            width_m: 0.8,
            mass_kg: 25.0,
            pocket_height_m: 0.1,
            blocks: block_grid([(-0.35, 0.1), (0.0, 0.145), (0.35, 0.1)], cols),
            notches: Vec::new(),
            entry: ALL_FACES.to_vec(),
        }
    }

    /// ISO 6780's 1200 × 1000 mm pallet as a nine-block, four-way pallet with 145 mm
    /// square blocks: openings of 282.5 mm on the 1000 mm faces (the front) and 382.5 mm on
    /// the 1200 mm faces, 100 mm high.
    pub fn iso_1200x1000() -> Self {
        let cols = [(0.0725, 0.145), (0.6, 0.145), (1.1275, 0.145)];
        Self {
            name: "iso-1200x1000".into(),
            depth_m: 1.2,
            width_m: 1.0,
            mass_kg: 30.0,
            pocket_height_m: 0.1,
            blocks: block_grid([(-0.4275, 0.145), (0.0, 0.145), (0.4275, 0.145)], cols),
            notches: Vec::new(),
            entry: ALL_FACES.to_vec(),
        }
    }

    /// GMA 48 × 40 in: three 1⅜ × 3½ in stringers 48 in long under a 40 in deck; the
    /// front is a 40 in face (two-way entry between the stringers, 3½ in high). Each
    /// stringer has two 9 in notches, 1½ in deep, 8½ in from its ends, which open the
    /// 48 in sides to forks thinner than the notch (partial four-way).
    pub fn gma_48x40() -> Self {
        let (depth, width, sw) = (48.0 * INCH_M, 40.0 * INCH_M, 1.375 * INCH_M);
        let o = (width - sw) / 2.0;
        let blocks = [-o, 0.0, o]
            .map(|y_m| PalletBlock {
                x_m: depth / 2.0,
                y_m,
                length_m: depth,
                width_m: sw,
            })
            .to_vec();
        let notch = |from_front_in: f64| PalletNotch {
            x_m: from_front_in * INCH_M,
            length_m: 9.0 * INCH_M,
            height_m: 1.5 * INCH_M,
        };
        Self {
            name: "gma-48x40".into(),
            depth_m: depth,
            width_m: width,
            mass_kg: 20.0,
            pocket_height_m: 3.5 * INCH_M,
            blocks,
            notches: vec![notch(13.0), notch(35.0)],
            entry: ALL_FACES.to_vec(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pockets(m: &PalletModel, face: PalletFace) -> (f64, f64) {
        let p = m.entered_from(face).expect("a valid pallet");
        (p.pocket_offsets_m()[0], p.pocket_width_m)
    }

    #[test]
    fn epal_openings_are_the_standards() {
        let m = PalletModel::epal_1();
        let (_, front) = pockets(&m, PalletFace::Front);
        let (_, side) = pockets(&m, PalletFace::Left);
        assert!((front - 0.2275).abs() < 1e-9, "{front}");
        assert!((side - 0.3825).abs() < 1e-9, "{side}");
        let p = m.entered_from(PalletFace::Right).expect("a valid pallet");
        assert_eq!((p.depth_m, p.width_m), (0.8, 1.2));
    }

    #[test]
    fn gma_sides_open_only_through_the_notches() {
        let m = PalletModel::gma_48x40();
        let (o, w) = pockets(&m, PalletFace::Front);
        assert!((w - (40.0 - 3.0 * 1.375) / 2.0 * INCH_M).abs() < 1e-9);
        assert!((o - (1.375 / 2.0 + (40.0 - 3.0 * 1.375) / 4.0) * INCH_M).abs() < 1e-9);
        let side = m.entered_from(PalletFace::Left).expect("a valid pallet");
        assert!((side.pocket_width_m - 9.0 * INCH_M).abs() < 1e-9);
        assert_eq!(side.pocket_height_m, Some(1.5 * INCH_M));
        // Three stringers, each cut in three.
        assert_eq!(side.parts().len(), 9);
        // Without its notches a stringer pallet's side has no pockets.
        let two_way = PalletModel {
            notches: Vec::new(),
            ..m
        };
        let e = two_way.entered_from(PalletFace::Left).expect_err("refused");
        assert!(e.reason.contains("0 gaps"), "{e}");
    }

    #[test]
    fn every_face_of_every_builtin_is_a_pallet() {
        for name in PalletModel::builtin_names() {
            let m = PalletModel::builtin(name).expect("built in");
            for face in ALL_FACES {
                let p = m.entered_from(face).expect("a valid pallet");
                p.validate().expect("a valid pallet");
                let [r, c, l] = p.face_solids();
                assert!(r[1] < c[0] && c[1] < l[0], "{name} {face:?}");
            }
        }
    }

    #[test]
    fn faces_the_kind_does_not_allow_and_bad_parts_are_refused() {
        let mut m = PalletModel::epal_1();
        m.entry = vec![PalletFace::Front, PalletFace::Back];
        let e = m.entered_from(PalletFace::Left).expect_err("refused");
        assert_eq!(e.field.as_deref(), Some("pallet_entry"));
        let mut m = PalletModel::epal_1();
        m.blocks[1].x_m = 0.1;
        let e = m.entered_from(PalletFace::Front).expect_err("refused");
        assert!(e.reason.contains("overlaps block[0]"), "{e}");
        let mut m = PalletModel::epal_1();
        m.blocks[0].y_m = -0.39;
        let e = m.entered_from(PalletFace::Front).expect_err("refused");
        assert_eq!(e.field.as_deref(), Some("block[0]"), "{e}");
    }
}
