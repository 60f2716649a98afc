//! `forkbench`: the command-line front end (parse, call the libraries, print).

mod accuracy_cmd;
mod batch_cmd;
mod out;
pub(crate) use out::{emit, emit_json_line};
mod check_cmd;
mod corridor_cmd;
mod coverage_cmd;
mod dataset_cmd;
mod detect_cmd;
mod gate_cmd;
mod map_cmd;
mod mission_report;
mod plan_cmd;
mod rare_cmd;
mod replay_cmd;
mod reproduce_cmd;
mod route_cmd;
mod run_options;
mod safety_cmd;
mod scan_cmd;
mod sequential_cmd;
mod trial_cmd;
mod truck_cmd;

use clap::{Parser, Subcommand, ValueEnum};
use forkbench_core::{ForkliftSpec, Pose2};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Parser)]
#[command(
    name = "forkbench",
    version,
    about = "Physics test bench for autonomous forklift pallet picking",
    after_help = "Exit status: 0 ok; 1 error or bad input; 2 usage; 3 the run worked and its \
                  result is a failure (a failed pick or mission, no path from a global `plan`, a \
                  regression in `regress`, a row \
                  below `batch --floor`)."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// The papers' tables `reproduce` knows.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum ReproduceArg {
    Bspline,
    Spiral,
    Corridor,
    Prm,
    /// The pallet detector's accuracy over range, angle and lateral offset.
    Detector,
}

/// Recording targets of one trial.
#[derive(Debug, clap::Args)]
pub(crate) struct RecordFlags {
    /// Write a rerun recording to FILE (.rrd); needs the CLI built with `--features rerun`.
    #[arg(long)]
    rrd: Option<PathBuf>,
    /// Write an MCAP log to FILE (.mcap).
    #[arg(long)]
    mcap: Option<PathBuf>,
    /// Write a ROS 2 bag to DIR: a rosbag2 directory (metadata.yaml and DIR_0.mcap, the
    /// ros2 profile: CDR messages, ros2msg schemas) that `ros2 bag play DIR` opens.
    #[arg(long, value_name = "DIR")]
    ros2: Option<PathBuf>,
    /// Write the actuator log to FILE (.csv: t_s, steer_cmd_rad, steer_rad, speed_cmd_mps,
    /// speed_mps at every physics step), what `identify` reads.
    #[arg(long, value_name = "FILE")]
    actuator_log: Option<PathBuf>,
    /// Spawn a rerun viewer and stream to it; needs the CLI built with `--features rerun`.
    #[arg(long)]
    rerun: bool,
    /// Stream to a running rerun viewer at HOST:PORT (e.g. 127.0.0.1:9876); needs the CLI
    /// built with `--features rerun`.
    #[arg(long)]
    connect: Option<String>,
    /// Overwrite existing recording files.
    #[arg(long)]
    force: bool,
}

impl RecordFlags {
    /// The targets, refused at once when they need rerun and this build has none.
    pub(crate) fn args(self) -> Result<forkbench_log::RecordTargets, forkbench_log::LogError> {
        let t = forkbench_log::RecordTargets {
            rrd: self.rrd,
            mcap: self.mcap,
            ros2: self.ros2,
            actuator_csv: self.actuator_log,
            rerun: self.rerun,
            connect: self.connect,
            force: self.force,
            inputs: Vec::new(),
        };
        t.check_built()?;
        Ok(t)
    }
}

/// `trial` and `mission`, as parsed.
#[derive(Debug, clap::Args)]
struct TrialCli {
    scenario: PathBuf,
    /// Case of the scenario (required when it has several).
    #[arg(long)]
    case: Option<String>,
    /// Seed of every random draw (default: the scenario's).
    #[arg(long)]
    seed: Option<u64>,
    /// Planner by name: the scenario's own or a registered kind (default: the scenario's).
    #[arg(long)]
    planner: Option<String>,
    /// Tracker by name: the scenario's own or a registered kind (default: the scenario's).
    #[arg(long)]
    tracker: Option<String>,
    /// Planners and trackers defined by name (`[[planner]]`, `[[tracker]]` tables) for
    /// --planner and --tracker, beside those of a components.toml next to the scenario.
    #[arg(long, value_name = "FILE")]
    components: Option<PathBuf>,
    /// Ideal sensors everywhere: no localisation, pallet-sensing or odometry error.
    #[arg(long)]
    no_noise: bool,
    /// Re-estimate the pallet at the configured ranges and replan when it moved.
    #[arg(long)]
    replan: bool,
    #[command(flatten)]
    options: run_options::RunOptionArgs,
    #[arg(long)]
    json: bool,
    /// Time each stage of the trial (physics, scans per sensor, detection and its
    /// evidence check, localisation, planning, tracking, criteria, safety, recording):
    /// printed after the outcome, and in --json as `profile`.
    #[arg(long)]
    profile: bool,
    #[command(flatten)]
    record: RecordFlags,
}

impl TrialCli {
    fn run(self, mission: bool) -> anyhow::Result<Done> {
        let overrides = self.options.overrides()?;
        let mut record = self.record.args()?;
        record.inputs.extend(self.options.truck_file());
        record.inputs.extend(self.components.clone());
        let opts = trial_cmd::options(
            self.seed,
            (self.planner, self.tracker),
            self.no_noise,
            self.replan,
            overrides,
        )?;
        let ok = trial_cmd::run(
            (&self.scenario, self.components.as_deref()),
            self.case.as_deref(),
            &opts,
            (self.json, mission, self.profile),
            &record,
        )?;
        Ok(if ok { Done::Ok } else { Done::PickFailed })
    }
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Plan one pick path from a start pose to a pallet pose, or a global route on a map
    /// (exit status 3 when the search ran and found no path).
    Plan(plan_cmd::PlanCli),
    /// Run one pick trial from a scenario file (exit status 3 when the pick fails).
    Trial(TrialCli),
    /// Run a warehouse mission (a scenario with a [mission] table): each leg, then the
    /// pick (exit status 3 when a leg or the pick fails).
    Mission(TrialCli),
    /// Re-run one trial from its JSON line (in a batch's trials.jsonl) and record it.
    Replay(replay_cmd::ReplayArgs),
    /// P(event) over a scenario's [[uncertain]] parameters with its confidence interval:
    /// cross-entropy importance sampling (or --method mc), every trial kept.
    Estimate(rare_cmd::EstimateArgs),
    /// The most likely failure over a scenario's [[uncertain]] parameters within a trial
    /// budget, and the least robust trial (exit 3 when a failure was found).
    Falsify(rare_cmd::FalsifyArgs),
    /// Monte-Carlo batch over scenarios × cases × planners × trackers × trials (default: the embedded scenario set).
    Batch(batch_cmd::BatchArgs),
    /// Combine shard outputs into one summary: shard directories, or the --out of a
    /// sharded batch (its shard-I-of-N directories).
    Merge {
        dirs: Vec<PathBuf>,
        #[arg(long)]
        out: PathBuf,
        #[arg(long)]
        json: bool,
    },
    /// Write a baseline from a results directory: success counts per row and every
    /// trial's key, seed and outcome (so a batch with the same seed compares pair by pair).
    Baseline {
        results: PathBuf,
        #[arg(long)]
        out: PathBuf,
        /// What the baseline is (default: "success counts from RESULTS").
        #[arg(long)]
        description: Option<String>,
    },
    /// The regression gate: results against a baseline, paired on common random numbers
    /// when the batch seed and settings match (McNemar's exact test), Holm-corrected over
    /// the rows at α 0.05. Exit 0 passed, 3 a row dropped (or failed the floor, is
    /// missing, or is underpowered), 1 bad input.
    Regress(gate_cmd::RegressArgs),
    /// A against B (two planners or two trackers run in one batch on shared seeds): a
    /// paired comparison per scenario and every trial they ended differently.
    Compare(gate_cmd::CompareArgs),
    /// Write a self-contained HTML report of a batch (or sweep) directory: DIR/report.html.
    Report {
        dir: PathBuf,
        /// Compare with this baseline, a verdict per row.
        #[arg(long)]
        baseline: Option<PathBuf>,
        /// Write the page here instead of DIR/report.html.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Corridor bends: minimum width per turning mode and angle, and G regions at a width.
    Corridor(corridor_cmd::CorridorCli),
    /// A world rasterised to an occupancy grid, written as a ROS map_server map (YAML + PGM).
    Map(map_cmd::MapArgs),
    /// One scan of a scenario's world from the truck, with the pallet detector's estimate
    /// beside the truth.
    Scan(scan_cmd::ScanArgs),
    /// A pallet detector on recorded scans (a ROS 2 bag's sensor_msgs/msg/LaserScan, or a
    /// forkbench MCAP): a JSON line per scan, a summary, and with --labels precision,
    /// recall and face-pose errors (exit 1 when a scan was unusable, after the rest).
    Detect(detect_cmd::DetectArgs),
    /// Labelled cluttered scans on demand: a ROS 2 bag and the labels detect --labels reads.
    Dataset(dataset_cmd::DatasetArgs),
    /// Reflector coverage of a world: reflectors in sight and the NAV350 fix's predicted
    /// 1σ at every free cell.
    Coverage(coverage_cmd::CoverageArgs),
    /// The safety scanner's protective field per speed range (ISO 3691-4 people
    /// detection): each term of the makers' formula, braking measured in the physics
    /// empty and at rated load on the scenario's floor.
    SafetyFields(safety_cmd::SafetyFieldsArgs),
    /// Fit the truck's steering and drive actuators (dead time, time constant, limits)
    /// from a CSV log of commands and measured responses, validated on held-out runs.
    Identify(truck_cmd::IdentifyArgs),
    /// Drive the simulated truck through seeded steering and speed steps and write the
    /// actuator log `identify` reads (a round trip with known actuators).
    StepTest(truck_cmd::StepTestArgs),
    /// Load a scenario as a run would and print what it resolved to: world, components,
    /// how the forks fit the pallet, limits and cases (exit 1 with the file, field and
    /// reason when it does not load).
    Check(check_cmd::CheckArgs),
    /// Reproduce a paper's table side by side with this project's results.
    Reproduce {
        what: ReproduceArg,
        /// Reference table (default: the embedded scenarios/reference/<planner>-table2.toml).
        #[arg(long)]
        table: Option<PathBuf>,
        #[arg(long)]
        json: bool,
        /// Draw all paths, curvature and steering to FILE (.svg or .png).
        #[arg(long)]
        plot: Option<PathBuf>,
        /// `reproduce detector`: scans per placement.
        #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u32).range(2..=10_000))]
        draws: u32,
    },
}

pub(crate) fn parse_pose(text: &str) -> Result<Pose2, String> {
    Pose2::parse_ui(text).map_err(|e| e.to_string())
}

/// Reads a forklift spec override file, or the A30 defaults.
pub(crate) fn load_truck(path: Option<&PathBuf>) -> anyhow::Result<ForkliftSpec> {
    let Some(path) = path else {
        return Ok(ForkliftSpec::default());
    };
    let text = read_input(path)?;
    let spec: ForkliftSpec =
        toml::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    spec.validate()
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    Ok(spec)
}

/// What a successful run reports: whether the work itself succeeded. Exit codes: 0 ok,
/// 1 error or bad input, 2 usage, 3 the run worked and its result is a failure (a failed
/// pick or mission, a regression).
enum Done {
    Ok,
    PickFailed,
    Regressed,
}

fn run(cli: Cli) -> anyhow::Result<Done> {
    match cli.command {
        Command::Batch(args) => {
            let ok = batch_cmd::run(args)?;
            Ok(if ok { Done::Ok } else { Done::Regressed })
        }
        Command::Report { dir, baseline, out } => {
            let out = out.unwrap_or_else(|| dir.join("report.html"));
            let page = forkbench_report::html::write_to(&dir, baseline.as_deref(), &out)?;
            emit(&format!("report written to {}\n", page.display())).map(|()| Done::Ok)
        }
        Command::Merge { dirs, out, json } => {
            batch_cmd::merge(&dirs, &out, json).map(|()| Done::Ok)
        }
        Command::Baseline {
            results,
            out,
            description,
        } => gate_cmd::baseline(&results, &out, description).map(|()| Done::Ok),
        Command::Regress(args) => {
            let ok = gate_cmd::regress(&args)?;
            Ok(if ok { Done::Ok } else { Done::Regressed })
        }
        Command::Compare(args) => gate_cmd::compare(&args).map(|()| Done::Ok),
        Command::Trial(t) => t.run(false),
        Command::Mission(t) => t.run(true),
        Command::Replay(a) => {
            let ok = replay_cmd::replay_args(a)?;
            Ok(if ok { Done::Ok } else { Done::PickFailed })
        }
        Command::Estimate(a) => rare_cmd::estimate(&a).map(|()| Done::Ok),
        Command::Falsify(a) => {
            let found = rare_cmd::falsify(a)?;
            Ok(if found { Done::PickFailed } else { Done::Ok })
        }
        Command::Plan(args) => match args.route()? {
            Some(route) => {
                route_cmd::run(&route).map(|found| if found { Done::Ok } else { Done::PickFailed })
            }
            None => plan_cmd::run(args.resolve()?).map(|()| Done::Ok),
        },
        Command::Reproduce {
            what,
            table,
            json,
            plot,
            draws,
        } => reproduce(&what, table.as_deref(), (json, draws), plot.as_deref()).map(|()| Done::Ok),
        Command::Corridor(args) => corridor_cmd::run(&args.resolve()?).map(|()| Done::Ok),
        Command::Map(args) => map_cmd::run(&args).map(|()| Done::Ok),
        Command::Scan(args) => scan_cmd::run(&args).map(|()| Done::Ok),
        Command::Coverage(args) => coverage_cmd::run(&args).map(|()| Done::Ok),
        Command::Detect(args) => detect_cmd::run(&args).map(|()| Done::Ok),
        Command::Dataset(args) => dataset_cmd::run(&args).map(|()| Done::Ok),
        Command::Check(args) => check_cmd::run(&args).map(|()| Done::Ok),
        Command::SafetyFields(args) => safety_cmd::run(&args).map(|()| Done::Ok),
        Command::Identify(args) => truck_cmd::identify(&args).map(|()| Done::Ok),
        Command::StepTest(args) => truck_cmd::step_test(&args).map(|()| Done::Ok),
    }
}

/// `reproduce WHAT`: the table of one paper, each from its own module.
fn reproduce(
    what: &ReproduceArg,
    table: Option<&std::path::Path>,
    (json, draws): (bool, u32),
    plot: Option<&std::path::Path>,
) -> anyhow::Result<()> {
    match what {
        ReproduceArg::Bspline | ReproduceArg::Spiral => {
            reproduce_cmd::run(matches!(what, ReproduceArg::Bspline), table, json, plot)
        }
        ReproduceArg::Corridor => {
            if table.is_some() {
                anyhow::bail!("--table: reproduce corridor has no reference table file");
            }
            corridor_cmd::reproduce(json, plot)
        }
        ReproduceArg::Prm => {
            if table.is_some() {
                anyhow::bail!("--table: reproduce prm has no reference table file");
            }
            route_cmd::reproduce(100, json, plot)
        }
        // --table: a scenario whose pallet and sensing are studied.
        ReproduceArg::Detector => accuracy_cmd::run(table, draws, json, plot),
    }
}

fn main() -> ExitCode {
    // A file-size limit (`ulimit -f`) must fail a write with an error the command reports,
    // naming the file, not kill the process and leave outputs half written: with a
    // handler installed, the write returns EFBIG instead.
    let _ = signal_hook::flag::register(
        signal_hook::consts::SIGXFSZ,
        std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false)),
    );
    kill_children_on_signals();
    // A detector's daemonised grandchild is reparented here, where the exit kills it.
    forkbench_ipc::adopt_orphans();
    let cli = Cli::parse();
    let result = run(cli);
    // No external process (or its children) outlives the command.
    forkbench_ipc::kill_all();
    let sig = INTERRUPTED.load(std::sync::atomic::Ordering::SeqCst);
    if sig != 0 {
        std::process::exit(128 + sig);
    }
    match result {
        Ok(Done::Ok) => ExitCode::SUCCESS,
        Ok(Done::PickFailed) => ExitCode::from(3),
        Ok(Done::Regressed) => ExitCode::from(3),
        Err(e) => {
            eprintln!(
                "error: {}",
                forkbench_trial::text::visible(&forkbench_trial::text::compact_numbers(&format!(
                    "{e:#}"
                )))
            );
            ExitCode::FAILURE
        }
    }
}

/// `scn` with the components `file` defines usable by name (`--components FILE`).
pub(crate) fn with_components(
    scn: forkbench_trial::Scenario,
    file: Option<&std::path::Path>,
) -> anyhow::Result<forkbench_trial::Scenario> {
    match file {
        Some(f) => Ok(scn.with_components_file(f)?),
        None => Ok(scn),
    }
}

/// Prints a scenario's likely slips (radians in a degrees key) as warnings.
pub(crate) fn warn_slips(scn: &forkbench_trial::Scenario) {
    for w in &scn.warnings {
        eprintln!("warning: {}", forkbench_trial::text::one_line(w));
    }
}

/// Largest settings file (truck spec, planner config, reference table) read: far above
/// any real one, a bound on what a wrong path can make the binary read.
const MAX_SETTINGS_BYTES: u64 = 4 << 20;

/// A user's input file through the one capped reader: regular files only (a FIFO or a
/// device is refused at once, naming it), at most [`MAX_SETTINGS_BYTES`].
pub(crate) fn read_input(path: &std::path::Path) -> anyhow::Result<String> {
    Ok(forkbench_core::files::read_text(path, MAX_SETTINGS_BYTES)?)
}

/// On an interrupt, a termination or a hang-up, every external planner, tracker and
/// detector (each in a process group of its own, which a terminal's Ctrl-C does not
/// reach) is killed with its group before forkbench exits with 128 + the signal; records
/// already written stay (each is flushed as it is written).
fn kill_children_on_signals() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        return;
    };
    std::thread::spawn(move || {
        if let Some(sig) = signals.forever().next() {
            // Set first: killing the children wakes the main thread, which must not
            // then exit with the failed run's status instead of the signal's.
            INTERRUPTED.store(sig, std::sync::atomic::Ordering::SeqCst);
            forkbench_ipc::kill_all();
            std::process::exit(128 + sig);
        }
    });
}

/// The signal that interrupted the run (0: none).
static INTERRUPTED: std::sync::atomic::AtomicI32 = std::sync::atomic::AtomicI32::new(0);
