//! The scenario's pallet: a built-in kind or a `[pallet_model]`, entered from one face.

use forkbench_core::PalletSpec;
use forkbench_core::pallet::{PalletBuild, PalletFace};

use super::checks::at_line;
use super::file::{PalletKind, ScenarioFile};
use super::{ScenarioError, invalid};

/// The pallet `f` names, as the truck meets it, and how to name it in messages
/// (`pallet_kind epal-1`, `pallet_model NAME`).
pub(super) fn resolve(
    f: &ScenarioFile,
    (file, text): (&str, &str),
) -> Result<(PalletSpec, String), ScenarioError> {
    let face = f.pallet_entry.unwrap_or(PalletFace::Front);
    let (model, label) = match (&f.pallet_model, f.pallet_kind) {
        (Some(_), Some(_)) => {
            return Err(invalid(
                &at_line(file, text, "pallet_kind"),
                "pallet_kind",
                "give either a built-in pallet_kind or a [pallet_model] table, not both",
            ));
        }
        (Some(m), None) => (m.clone(), format!("pallet_model {}", m.name)),
        (None, kind) => {
            let kind = kind.unwrap_or_else(PalletKind::field_1200);
            let label = format!("pallet_kind {}", kind.name());
            match kind.0.build {
                PalletBuild::Parts(model) => (model(), label),
                PalletBuild::Stringers(spec) => {
                    return stringer_kind(f, spec(), face, label, (file, text));
                }
            }
        }
    };
    let custom = f.pallet_model.is_some();
    let at = if custom {
        "[pallet_model]"
    } else {
        "pallet_entry"
    };
    let spec = model.entered_from(face).map_err(|e| {
        let field = match (e.field.as_deref(), custom) {
            (Some("pallet_entry"), _) => "pallet_entry".to_owned(),
            (_, false) => "pallet_kind".to_owned(),
            (Some(k), true) => format!("pallet_model.{k}"),
            (None, true) => "pallet_model".to_owned(),
        };
        invalid(&at_line(file, text, at), &field, &e.reason)
    })?;
    let label = format!("{label}, {} face", face.name());
    Ok((spec.with_payload(f.payload_kg), label))
}

/// The two stringer pallets of the papers: two-way, entered from the front or the back
/// (the same by symmetry).
fn stringer_kind(
    f: &ScenarioFile,
    spec: PalletSpec,
    face: PalletFace,
    label: String,
    (file, text): (&str, &str),
) -> Result<(PalletSpec, String), ScenarioError> {
    if matches!(face, PalletFace::Left | PalletFace::Right) {
        return Err(invalid(
            &at_line(file, text, "pallet_entry"),
            "pallet_entry",
            &format!(
                "{label} is a two-way stringer pallet: its {} side has no pockets (entry faces: front, back)",
                face.name()
            ),
        ));
    }
    let label = format!("{label}, {} face", face.name());
    Ok((spec.with_payload(f.payload_kg), label))
}

/// Forks thicker than the pocket opening cannot enter it: refused when the truck gives
/// its fork thickness and the pallet its pocket height.
pub(super) fn check_thickness(
    f: &ScenarioFile,
    (pallet, label): (&PalletSpec, &str),
    file: &str,
) -> Result<(), ScenarioError> {
    let (Some(t), Some(h)) = (f.truck.fork_thickness_m, pallet.pocket_height_m) else {
        return Ok(());
    };
    if t < h {
        return Ok(());
    }
    Err(invalid(
        file,
        "truck.fork_thickness_m",
        &format!(
            "{t} m forks do not fit the {h:.4} m high pockets of the pallet ({label}); use thinner forks or another face"
        ),
    ))
}
