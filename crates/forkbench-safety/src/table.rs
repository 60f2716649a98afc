//! The sizing as a text table a safety integrator reads: one row per field set and load, every term of the formula in millimetres.

use std::fmt::Write as _;

use crate::FieldSizing;

/// Column headers, in the formula's order.
const HEAD: [&str; 13] = [
    "v_max", "load", "S_Br", "S_AnF", "S_AnS", "S_A", "TZ", "Z_R", "Z_F", "Z_G", "Z_B", "S_L",
    "S_B",
];

/// The table, preceded by what it assumed.
pub fn text(s: &FieldSizing) -> String {
    let c = &s.config;
    let mut out = format!(
        "protective fields (mm; v_max in m/s): scanner TZ {:.0} mm, response {:.0} ms, \
         resolution {:.0} mm; controller {:.0} ms; floor μ {}; Z_R {} (reflectors {}), \
         ground clearance {:.0} mm\n",
        c.scanner.tolerance_m * 1e3,
        c.scanner.response_time_s * 1e3,
        c.scanner.resolution_m * 1e3,
        c.controller_response_s * 1e3,
        s.tyre_friction,
        if s.reflectors_near {
            "applied"
        } else {
            "not applied"
        },
        if s.reflectors_near { "near" } else { "absent" },
        c.ground_clearance_m * 1e3,
    );
    let line = |cells: Vec<String>| {
        let mut l = String::new();
        for cell in &cells {
            let _ = write!(l, "{cell:>6} ");
        }
        l.trim_end().to_owned() + "\n"
    };
    out += &line(HEAD.iter().map(|h| (*h).to_owned()).collect());
    for f in &s.fields {
        let mm = |m: f64| format!("{:.0}", m * 1e3);
        let mut cells = vec![format!("{:.2}", f.speed_max_mps), f.load.name().to_owned()];
        cells.extend(
            [
                f.braking_m,
                f.controller_m,
                f.scanner_m,
                f.stopping_m,
                f.tolerance_m,
                f.reflector_m,
                f.floor_m,
                f.general_m,
                f.braking_supplement_m,
                f.length_m,
                f.width_m,
            ]
            .map(mm),
        );
        out += &line(cells);
    }
    out
}

/// Each drawn field set (`[[safety.field_set]]`) against the sizing: how far its
/// protective field reaches straight beyond the truck's leading edge, and S_L for its
/// range (the worse of empty and rated).
pub fn drawn_text(s: &FieldSizing, truck: &crate::Footprint) -> String {
    let mut out = String::new();
    for d in &s.config.field_set {
        let s_l = s
            .fields
            .iter()
            .filter(|f| f.speed_max_mps == d.speed_max_mps)
            .map(|f| f.length_m)
            .fold(0.0, f64::max);
        let reach = d.reach_m(truck);
        let verdict = if reach + 1e-9 < s_l {
            format!("SHORTER than S_L by {:.0} mm", (s_l - reach) * 1e3)
        } else {
            "at least S_L".to_owned()
        };
        let _ = writeln!(
            out,
            "drawn field set {:.2} m/s {}: protective field reaches {:.0} mm beyond the \
             leading edge (S_L {:.0} mm): {verdict}",
            d.speed_max_mps,
            d.direction.name(),
            reach * 1e3,
            s_l * 1e3
        );
    }
    out
}
