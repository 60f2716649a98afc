//! Builds the recording sinks a command asked for (--rrd, --mcap, --rerun, --connect).

use std::collections::BTreeMap;
use std::path::PathBuf;

use forkbench_log::{
    LogError, McapRecorder, RerunRecorder, RerunTarget, Ros2Recorder, check_writable,
};
use forkbench_trial::{Recorder, Tee};

/// What to record to.
#[derive(Debug, Clone, Default)]
pub struct RecordArgs {
    pub rrd: Option<PathBuf>,
    pub mcap: Option<PathBuf>,
    /// A ROS 2 bag (MCAP, `ros2` profile).
    pub ros2: Option<PathBuf>,
    pub rerun: bool,
    pub connect: Option<String>,
    pub force: bool,
}

/// Opened sinks: the file-backed ones keep typed handles so they can be finished and
/// their errors reported; a viewer that could not be reached is reported, not fatal.
pub struct Sinks {
    pub mcap: Option<McapRecorder>,
    pub ros2: Option<Ros2Recorder>,
    pub rerun: Vec<RerunRecorder>,
    pub viewer_error: Option<LogError>,
}

impl Sinks {
    /// Checks file targets before anything runs, then opens every sink.
    pub fn open(a: &RecordArgs, metadata: BTreeMap<String, String>) -> Result<Self, LogError> {
        let files: Vec<&PathBuf> = a.rrd.iter().chain(&a.mcap).chain(&a.ros2).collect();
        for (i, p) in files.iter().enumerate() {
            if files[..i]
                .iter()
                .any(|q| std::path::absolute(q).ok() == std::path::absolute(p).ok())
            {
                return Err(LogError::Io {
                    path: p.display().to_string(),
                    message: "given to two of --rrd, --mcap and --ros2; each format needs its \
                              own file"
                        .into(),
                });
            }
            check_writable(p, a.force)?;
        }
        let mut rerun = Vec::new();
        if let Some(p) = &a.rrd {
            rerun.push(RerunRecorder::new(&RerunTarget::File(p.clone()))?);
        }
        let mut viewer_error = None;
        let viewer = match (&a.connect, a.rerun) {
            (Some(addr), _) => Some(RerunTarget::Connect(addr.clone())),
            (None, true) => Some(RerunTarget::Spawn),
            (None, false) => None,
        };
        if let Some(target) = viewer {
            match RerunRecorder::new(&target) {
                Ok(r) => rerun.push(r),
                Err(e) => viewer_error = Some(e),
            }
        }
        let ros2 = a
            .ros2
            .as_ref()
            .map(|p| Ros2Recorder::create(p, metadata.clone()))
            .transpose()?;
        let mcap = a
            .mcap
            .as_ref()
            .map(|p| McapRecorder::create(p, metadata))
            .transpose()?;
        Ok(Self {
            mcap,
            ros2,
            rerun,
            viewer_error,
        })
    }

    /// Runs `f` with every open sink behind one recorder, then finishes them all.
    pub fn record<T>(
        &mut self,
        f: impl FnOnce(&mut dyn Recorder) -> T,
    ) -> (T, Result<(), LogError>) {
        let out = {
            let mut refs: Vec<&mut dyn Recorder> = Vec::new();
            if let Some(m) = self.mcap.as_mut() {
                refs.push(m);
            }
            if let Some(m) = self.ros2.as_mut() {
                refs.push(m);
            }
            for r in self.rerun.iter_mut() {
                refs.push(r);
            }
            f(&mut Tee(refs))
        };
        let mut result = Ok(());
        if let Some(m) = self.mcap.as_mut()
            && let Err(e) = m.finish()
        {
            result = Err(e);
        }
        if let Some(m) = self.ros2.as_mut()
            && let Err(e) = m.finish()
            && result.is_ok()
        {
            result = Err(e);
        }
        for r in self.rerun.iter_mut() {
            if let Err(e) = r.finish()
                && result.is_ok()
            {
                result = Err(e);
            }
        }
        (out, result)
    }
}

/// Metadata record of a trial's MCAP file.
pub fn metadata(
    scenario: &str,
    case: &str,
    run: &forkbench_trial::Resolved,
) -> BTreeMap<String, String> {
    forkbench_log::mcap_metadata(
        [scenario, case, &run.planner.name, &run.tracker.name],
        run.seed,
        env!("CARGO_PKG_VERSION"),
    )
}

/// The file stem of a trial's recordings: `<scenario>-<case>-<planner>-<tracker>-seed<seed>`,
/// with `-replan` for a trial that replans (both modes of a batch run the same seeds).
pub fn recording_stem(o: &forkbench_trial::TrialOutcome, replan: bool) -> String {
    let mode = if replan { "-replan" } else { "" };
    safe_file_stem(&format!(
        "{}-{}-{}-{}-seed{}{mode}",
        o.scenario, o.case, o.planner, o.tracker, o.seed
    ))
}

/// Re-runs one trial of a scenario into `<dir>/<stem>.{rrd,mcap}` ([`recording_stem`]),
/// and `<stem>.ros2.mcap` with `ros2`.
pub fn record_trial(
    scn: &forkbench_trial::Scenario,
    case: &forkbench_trial::Case,
    opts: &forkbench_trial::TrialOptions,
    dir: &std::path::Path,
    ros2: bool,
) -> anyhow::Result<(forkbench_trial::TrialOutcome, PathBuf)> {
    let run = scn.resolve(opts)?;
    // Names are free text: only letters, digits, '-' and '_' reach the file name, so a
    // name can neither leave `dir` nor fail the write (the real names are in the files).
    let names = (run.planner.name.as_str(), run.tracker.name.as_str());
    let id =
        forkbench_trial::TrialOutcome::blank(&scn.name, &case.name, names, run.seed, run.noise);
    let stem = recording_stem(&id, run.replan);
    let rrd = dir.join(format!("{stem}.rrd"));
    let args = RecordArgs {
        rrd: Some(rrd.clone()),
        mcap: Some(dir.join(format!("{stem}.mcap"))),
        ros2: ros2.then(|| dir.join(format!("{stem}.ros2.mcap"))),
        force: true,
        ..RecordArgs::default()
    };
    let mut sinks = Sinks::open(&args, metadata(&scn.name, &case.name, &run))?;
    let (out, written) =
        sinks.record(|rec| forkbench_trial::run_trial_recorded(scn, case, opts, rec));
    written?;
    Ok((out, rrd))
}

/// `text` with every character other than ASCII letters, digits, '-' and '_' replaced by '_'.
pub fn safe_file_stem(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}
