//! The recording sinks a run asks for (an .rrd, an MCAP, a ROS 2 bag, a viewer, an actuator log), opened together and fed one trial.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use forkbench_trial::{
    Case, Recorder, Resolved, Scenario, ScenarioError, Tee, TrialOptions, TrialOutcome,
};

use crate::{ActuatorCsv, LogError, McapRecorder, Ros2Recorder, check_writable};
#[cfg(feature = "rerun")]
use crate::{RerunRecorder, RerunTarget};

/// What to record to.
#[derive(Debug, Clone, Default)]
pub struct RecordTargets {
    pub rrd: Option<PathBuf>,
    pub mcap: Option<PathBuf>,
    /// A ROS 2 bag: a rosbag2 directory (`metadata.yaml` and an MCAP, `ros2` profile).
    pub ros2: Option<PathBuf>,
    /// The actuator log as CSV (what `forkbench identify` reads).
    pub actuator_csv: Option<PathBuf>,
    /// Spawn a rerun viewer.
    pub rerun: bool,
    /// A running rerun viewer at HOST:PORT.
    pub connect: Option<String>,
    /// Overwrite existing recording files.
    pub force: bool,
    /// The files the run reads (scenario, world, truck, components): no recording may
    /// replace one, `force` or not.
    pub inputs: Vec<PathBuf>,
}

/// A trial that could not be recorded: its options, or a sink.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    #[error(transparent)]
    Trial(#[from] ScenarioError),
    #[error(transparent)]
    Log(#[from] LogError),
}

/// Opened sinks: the file-backed ones keep typed handles so they can be finished and
/// their errors reported; a viewer that could not be reached is reported, not fatal.
pub struct Sinks {
    pub mcap: Option<McapRecorder>,
    pub ros2: Option<Ros2Recorder>,
    pub actuator_csv: Option<ActuatorCsv>,
    #[cfg(feature = "rerun")]
    pub rerun: Vec<RerunRecorder>,
    pub viewer_error: Option<LogError>,
}

impl std::fmt::Debug for Sinks {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Sinks")
            .field("mcap", &self.mcap.is_some())
            .field("ros2", &self.ros2.is_some())
            .field("viewer_error", &self.viewer_error)
            .finish_non_exhaustive()
    }
}

impl Sinks {
    /// Checks file targets before anything runs, then opens every sink.
    pub fn open(a: &RecordTargets, metadata: BTreeMap<String, String>) -> Result<Self, LogError> {
        a.check_built()?;
        let files: Vec<&PathBuf> = a
            .rrd
            .iter()
            .chain(&a.mcap)
            .chain(&a.ros2)
            .chain(&a.actuator_csv)
            .collect();
        for (i, p) in files.iter().enumerate() {
            if files[..i]
                .iter()
                .any(|q| std::path::absolute(q).ok() == std::path::absolute(p).ok())
            {
                return Err(LogError::Io {
                    path: p.display().to_string(),
                    message: "given to two of --rrd, --mcap, --ros2 and --actuator-log; each \
                              output needs its own file"
                        .into(),
                });
            }
            forkbench_core::files::check_not_input(p, &a.inputs).map_err(|e| LogError::Io {
                path: p.display().to_string(),
                message: match e {
                    forkbench_core::files::FileError::IsInput { input, .. } => {
                        format!("is {input}, which this run reads; give the recording another name")
                    }
                    other => other.to_string(),
                },
            })?;
            if a.ros2.as_ref() == Some(*p) {
                crate::ros2::check_bag_dir(p, a.force)?;
            } else {
                check_writable(p, a.force)?;
            }
        }
        let (rerun, viewer_error) = open_rerun(a)?;
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
        #[cfg(not(feature = "rerun"))]
        let () = rerun;
        Ok(Self {
            mcap,
            ros2,
            actuator_csv: a.actuator_csv.as_deref().map(ActuatorCsv::create),
            #[cfg(feature = "rerun")]
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
            if let Some(m) = self.actuator_csv.as_mut() {
                refs.push(m);
            }
            #[cfg(feature = "rerun")]
            for r in self.rerun.iter_mut() {
                refs.push(r);
            }
            f(&mut Tee(refs))
        };
        let mut result = self.mcap.as_mut().map_or(Ok(()), McapRecorder::finish);
        if let Some(m) = self.ros2.as_mut()
            && let Err(e) = m.finish()
            && result.is_ok()
        {
            result = Err(e);
        }
        if let Some(m) = self.actuator_csv.as_mut()
            && let Err(e) = m.finish()
            && result.is_ok()
        {
            result = Err(e);
        }
        #[cfg(feature = "rerun")]
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

/// The rerun sinks asked for: the .rrd file (an error when it cannot be made), and a
/// viewer (its error kept to report: the trial runs without it).
#[cfg(feature = "rerun")]
fn open_rerun(a: &RecordTargets) -> Result<(Vec<RerunRecorder>, Option<LogError>), LogError> {
    let mut rerun = Vec::new();
    if let Some(p) = &a.rrd {
        rerun.push(RerunRecorder::new(&RerunTarget::File(p.clone()))?);
    }
    let viewer = match (&a.connect, a.rerun) {
        (Some(addr), _) => Some(RerunTarget::Connect(addr.clone())),
        (None, true) => Some(RerunTarget::Spawn),
        (None, false) => None,
    };
    let mut viewer_error = None;
    if let Some(target) = viewer {
        match RerunRecorder::new(&target) {
            Ok(r) => rerun.push(r),
            Err(e) => viewer_error = Some(e),
        }
    }
    Ok((rerun, viewer_error))
}

/// Without rerun an .rrd or a viewer is refused (by `Sinks::open`, first), never dropped.
#[cfg(not(feature = "rerun"))]
fn open_rerun(a: &RecordTargets) -> Result<((), Option<LogError>), LogError> {
    a.check_built()?;
    Ok(((), None))
}

impl RecordTargets {
    /// Whether this build can write what the targets ask for: an .rrd or a viewer needs
    /// rerun, which the default build leaves out (its SDK is most of a cold build). Checked
    /// before a run starts, so no campaign runs to then fail at its recording.
    pub fn check_built(&self) -> Result<(), LogError> {
        let wants = [
            self.rrd.as_ref().map(|_| "--rrd"),
            self.rerun.then_some("--rerun"),
            self.connect.as_ref().map(|_| "--connect"),
        ];
        match wants.into_iter().flatten().next() {
            Some(flag) if !crate::HAS_RERUN => Err(LogError::Rerun(format!(
                "{flag} needs rerun, which this build of forkbench leaves out (rerun's SDK is \
                 most of a cold build); build the command line with `--features rerun`: cargo \
                 run --release -p forkbench-cli --features rerun -- … (MCAP and ROS 2 bags are \
                 written either way)"
            ))),
            _ => Ok(()),
        }
    }
}

/// Metadata record of a trial's MCAP file.
pub fn metadata(scenario: &str, case: &str, run: &Resolved) -> BTreeMap<String, String> {
    crate::mcap_metadata(
        [scenario, case, &run.planner.name, &run.tracker.name],
        run.seed,
        env!("CARGO_PKG_VERSION"),
    )
}

/// One trial run into the sinks: its outcome (computed even when a sink failed), whether
/// every file was written, and a viewer that could not be reached.
#[derive(Debug)]
pub struct Recorded {
    pub outcome: TrialOutcome,
    pub written: Result<(), LogError>,
    pub viewer_error: Option<LogError>,
}

/// Opens `targets` (file targets checked before the run) and runs one trial into them;
/// `run` is `opts` resolved against `scn` (what the MCAP's metadata names).
pub fn run_recorded(
    (scn, case): (&Scenario, &Case),
    (opts, run): (&TrialOptions, &Resolved),
    targets: &RecordTargets,
) -> Result<Recorded, LogError> {
    let mut targets = targets.clone();
    targets.inputs.extend(scn.files().iter().cloned());
    let mut sinks = Sinks::open(&targets, metadata(&scn.name, &case.name, run))?;
    let (outcome, written) =
        sinks.record(|rec| forkbench_trial::run_trial_recorded(scn, case, opts, rec));
    Ok(Recorded {
        outcome,
        written,
        viewer_error: sinks.viewer_error.take(),
    })
}

/// Re-runs one trial of a scenario into `<dir>/<stem>.mcap`, and `<stem>.rrd` in a build with
/// rerun (the stem is [`TrialOutcome::recording_stem`]), and the bag directory `<stem>.ros2`
/// with `ros2`; returns the outcome and the .rrd's path (the MCAP's without rerun).
pub fn record_trial(
    scn: &Scenario,
    case: &Case,
    opts: &TrialOptions,
    dir: &Path,
    ros2: bool,
) -> Result<(TrialOutcome, PathBuf), RecordError> {
    let run = opts.resolve(scn)?;
    // Names are free text: the stem keeps only letters, digits, '-' and '_', so a name
    // can neither leave `dir` nor fail the write (the real names are in the files).
    let names = (run.planner.name.as_str(), run.tracker.name.as_str());
    let stem = TrialOutcome::blank(&scn.name, &case.name, names, run.seed, run.noise)
        .recording_stem(run.replan);
    // The .rrd when this build has rerun, and the MCAP always.
    let rrd = crate::HAS_RERUN.then(|| dir.join(format!("{stem}.rrd")));
    let mcap = dir.join(format!("{stem}.mcap"));
    let targets = RecordTargets {
        rrd: rrd.clone(),
        mcap: Some(mcap.clone()),
        ros2: ros2.then(|| dir.join(format!("{stem}.ros2"))),
        force: true,
        ..RecordTargets::default()
    };
    let r = run_recorded((scn, case), (opts, &run), &targets)?;
    r.written?;
    Ok((r.outcome, rrd.unwrap_or(mcap)))
}
