//! Trial records as CSV: one row per trial, flat columns in SI units, for pandas, polars or R.

use std::path::Path;

use serde::Serialize;

use super::{BatchError, TrialRecord};
use forkbench_trial::text::csv_text;
use forkbench_trial::trial::Overrides;

/// A CSV row's first columns: the trial's identity.
#[derive(Debug, Serialize)]
struct Head {
    scenario: String,
    case: String,
    planner: String,
    tracker: String,
    trial: u64,
    seed: u64,
    noise: bool,
    replan: Option<bool>,
}

/// The rest of a CSV row, after the run's options (column names carry their units).
#[derive(Debug, Serialize)]
struct Row<'a> {
    success: bool,
    failure: &'a str,
    failure_detail: String,
    lateral_error_m: Option<f64>,
    heading_error_rad: Option<f64>,
    final_lateral_error_m: Option<f64>,
    final_heading_error_rad: Option<f64>,
    insertion_depth_m: Option<f64>,
    max_steer_rad: f64,
    max_contact_force_n: f64,
    pallet_displacement_m: f64,
    pallet_rotation_rad: f64,
    replans: u32,
    replans_failed: u32,
    path_length_m: f64,
    sim_time_s: f64,
    wall_time_ms: f64,
    /// Signed margin to failure (the outcome's `robustness`).
    robustness: Option<f64>,
    /// Handling cycles: the phases that succeeded, the first that failed, the totals.
    phases_done: Option<usize>,
    failed_phase: &'a str,
    cycle_time_s: Option<f64>,
    distance_loaded_m: Option<f64>,
    distance_unloaded_m: Option<f64>,
}

/// Writes `records` to `path` as CSV (sorted by trial key), atomically; a value not
/// measured (the trial ended before it) is an empty cell. Text cells are neutralised
/// against spreadsheet formulas and control characters ([`csv_text`]).
pub fn write_csv(records: &[TrialRecord], path: &Path) -> Result<(), BatchError> {
    let mut sorted: Vec<&TrialRecord> = records.iter().collect();
    sorted.sort_by_key(|r| r.key());
    let mut w = csv::Writer::from_writer(Vec::new());
    // The step criteria's measurements follow the fixed columns, one column each: the
    // built-in ones, then any a registered criterion wrote, by name.
    let mut measures: Vec<&str> = forkbench_trial::trial::step_measures();
    let extra: std::collections::BTreeSet<&str> = sorted
        .iter()
        .flat_map(|r| r.outcome.measures.keys().map(String::as_str))
        .filter(|k| !measures.contains(k))
        .collect();
    measures.extend(extra);
    // Safety columns only in batches with people or safety fields, so others keep theirs.
    let safety = sorted.iter().any(|r| r.outcome.safety.is_some());
    let mut header_written = false;
    let finite = |v: f64| v.is_finite().then_some(v);
    for r in sorted {
        let o = &r.outcome;
        let (header, mut record) = cells(r, finite).map_err(|e| csv_error(path, e))?;
        if !header_written {
            let mut h = header;
            h.extend(measures.iter().copied());
            if safety {
                h.extend(SAFETY_COLUMNS);
            }
            w.write_record(&h).map_err(|e| csv_error(path, e))?;
            header_written = true;
        }
        for m in &measures {
            record.push_field(&o.measures.get(*m).map_or(String::new(), |v| v.to_string()));
        }
        if safety {
            for cell in safety_cells(o.safety.as_ref()) {
                record.push_field(&cell);
            }
        }
        w.write_record(&record).map_err(|e| csv_error(path, e))?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| BatchError::Internal(format!("{}: {e}", path.display())))?;
    super::write_atomic(path, &bytes)
}

/// The safety columns, after the step criteria's.
const SAFETY_COLUMNS: [&str; 7] = [
    "safety_stops",
    "safety_false_trips",
    "safety_stop_time_s",
    "safety_slowdowns",
    "safety_slowdown_time_s",
    "person_contacts",
    "closest_person_m",
];

/// A trial's safety cells (empty without people or fields).
fn safety_cells(s: Option<&forkbench_trial::SafetyOutcome>) -> [String; 7] {
    let Some(s) = s else {
        return Default::default();
    };
    [
        s.stops.to_string(),
        s.false_trips.to_string(),
        s.stop_time_s.to_string(),
        s.slowdowns.to_string(),
        s.slowdown_time_s.to_string(),
        s.person_contacts.to_string(),
        s.closest_any_m().map_or(String::new(), |v| v.to_string()),
    ]
}

/// A trial's column names and cells before the measures: its identity, the run's options
/// (one column per field of [`Overrides`], by its name), then its outcome.
fn cells(
    r: &TrialRecord,
    finite: impl Fn(f64) -> Option<f64>,
) -> Result<(csv::StringRecord, csv::StringRecord), csv::Error> {
    let o = &r.outcome;
    let head = Head {
        scenario: csv_text(&o.scenario),
        case: csv_text(&o.case),
        planner: csv_text(&o.planner),
        tracker: csv_text(&o.tracker),
        trial: r.trial,
        seed: o.seed,
        noise: o.noise,
        replan: r.replan,
    };
    let (mut header, mut record) = fields(&head)?;
    let options = serde_json::to_value(&r.overrides).unwrap_or_default();
    for name in Overrides::field_names() {
        header.push_field(name);
        record.push_field(&option_cell(options.get(name)));
    }
    let (h, rest) = fields(&row(r, finite))?;
    header.extend(h.iter());
    record.extend(rest.iter());
    Ok((header, record))
}

/// One option's cell: empty when unset; a list joined by `;`, settings as `key=value;…`.
fn option_cell(v: Option<&serde_json::Value>) -> String {
    use serde_json::Value;
    match v {
        None | Some(Value::Null) => String::new(),
        Some(Value::String(s)) => csv_text(s),
        Some(Value::Array(items)) => {
            let parts: Vec<String> = items.iter().map(|i| option_cell(Some(i))).collect();
            parts.join(";")
        }
        Some(Value::Object(map)) => {
            let parts: Vec<String> = map
                .iter()
                .map(|(k, v)| format!("{}={}", csv_text(k), option_cell(Some(v))))
                .collect();
            parts.join(";")
        }
        Some(other) => other.to_string(),
    }
}

/// A row's column names and values, as csv writes them.
fn fields<T: Serialize>(row: &T) -> Result<(csv::StringRecord, csv::StringRecord), csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.serialize(row)?;
    let bytes = w.into_inner().map_err(|e| e.into_error())?;
    let mut rd = csv::Reader::from_reader(bytes.as_slice());
    let header = rd.headers()?.clone();
    let record = rd.records().next().transpose()?.unwrap_or_default();
    Ok((header, record))
}

fn row<'a>(r: &'a TrialRecord, finite: impl Fn(f64) -> Option<f64>) -> Row<'a> {
    let o = &r.outcome;
    Row {
        success: o.success,
        failure: o.failure.as_ref().map_or("", |f| f.name()),
        failure_detail: csv_text(o.failure_detail.as_deref().unwrap_or("")),
        lateral_error_m: o.lateral_error_m,
        heading_error_rad: o.heading_error_rad,
        final_lateral_error_m: finite(o.final_lateral_error_m),
        final_heading_error_rad: finite(o.final_heading_error_rad),
        insertion_depth_m: finite(o.insertion_depth_m),
        max_steer_rad: o.max_steer_rad,
        max_contact_force_n: o.max_contact_force_n,
        pallet_displacement_m: o.pallet_displacement_m,
        pallet_rotation_rad: o.pallet_rotation_rad,
        replans: o.replans,
        replans_failed: o.replans_failed,
        path_length_m: o.path_length_m,
        sim_time_s: o.sim_time_s,
        wall_time_ms: o.wall_time_ms,
        robustness: o.robustness,
        phases_done: (!o.phases.is_empty()).then(|| o.phases.iter().filter(|p| p.success).count()),
        failed_phase: o
            .phases
            .iter()
            .find(|p| !p.success)
            .map_or("", |p| p.name.as_str()),
        cycle_time_s: o.cycle.map(|c| c.time_s),
        distance_loaded_m: o.cycle.map(|c| c.distance_loaded_m),
        distance_unloaded_m: o.cycle.map(|c| c.distance_unloaded_m),
    }
}

fn csv_error(path: &Path, e: csv::Error) -> BatchError {
    BatchError::Internal(format!("{}: writing CSV: {e}", path.display()))
}
