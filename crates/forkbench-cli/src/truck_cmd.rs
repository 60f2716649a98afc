//! The truck's actuators from the command line: `--truck PRESET|FILE` for a run.

/// A `--truck` argument as a run's changes to the truck: a preset by name, or a truck
/// file's preset and settings; refused naming the file and the field.
pub(crate) fn truck_settings(
    arg: Option<&str>,
) -> anyhow::Result<(Option<String>, std::collections::BTreeMap<String, f64>)> {
    let Some(arg) = arg else {
        return Ok((None, Default::default()));
    };
    if forkbench_core::actuators::Actuators::preset(arg).is_some() {
        return Ok((Some(arg.to_owned()), Default::default()));
    }
    let path = std::path::PathBuf::from(arg);
    if !path.exists() {
        let known: Vec<&str> = forkbench_core::actuators::PRESETS
            .iter()
            .map(|(n, _)| *n)
            .collect();
        anyhow::bail!(
            "--truck {arg:?}: neither a preset ({}) nor a file",
            known.join(", ")
        );
    }
    let text = crate::read_input(&path)?;
    // Names, lines and ranges checked here, so an error names the file it is in.
    let f = forkbench_trial::trial::read_truck_text(&text, &path.display().to_string())?;
    Ok((f.preset, f.settings))
}

/// `forkbench identify LOG`: the truck's actuators fitted from a log.
#[derive(Debug, clap::Args)]
pub struct IdentifyArgs {
    /// CSV log with a header naming `t_s`, `steer_cmd_rad`, `steer_rad`, `speed_cmd_mps`,
    /// `speed_mps` (either channel may be missing; other columns ignored; a `run` column
    /// separates runs, which are held out whole for validation).
    log: std::path::PathBuf,
    /// Print the fit as JSON.
    #[arg(long)]
    json: bool,
    /// Write the fitted settings as a truck file that `--truck` takes.
    #[arg(long, value_name = "FILE")]
    truck_out: Option<std::path::PathBuf>,
    /// Draw each channel's held-out run, measured against fitted (.svg or .png).
    #[arg(long, value_name = "FILE")]
    plot: Option<std::path::PathBuf>,
    /// For an .mcap log or ROS 2 bag: the topic whose messages (JSON, or CDR by the bag's
    /// own definitions) time the samples (forkbench's recordings keep them on
    /// /forkbench/telemetry; its ROS 2 bags, found without this, on
    /// /forkbench/actuators/command and /forkbench/actuators/measured).
    #[arg(long, default_value = forkbench_identify::mcap_log::TELEMETRY_TOPIC)]
    topic: String,
    /// For an .mcap log: five comma-separated fields holding t_s, steer_cmd_rad,
    /// steer_rad, speed_cmd_mps, speed_mps, in that order: dotted paths into the topic's
    /// messages (a ROS 2 Time as seconds), `/other_topic:path` for a field of another topic
    /// (its latest value at each sample), `@log_time` for the message's log time, and an
    /// empty name to leave a channel out.
    #[arg(long, value_delimiter = ',', value_name = "FIELDS",
          default_values_t = forkbench_identify::log::COLUMNS.map(str::to_owned))]
    fields: Vec<String>,
}

pub fn identify(a: &IdentifyArgs) -> anyhow::Result<()> {
    use anyhow::Context as _;
    let outputs = [("--truck-out", &a.truck_out), ("--plot", &a.plot)];
    for (flag, out) in outputs {
        if let Some(out) = out
            && forkbench_core::files::same_file(&a.log, out)
        {
            anyhow::bail!(
                "{flag} {}: is the log being identified; writing there would destroy it",
                out.display()
            );
        }
    }
    if let (Some(t), Some(p)) = (&a.truck_out, &a.plot)
        && (t == p || forkbench_core::files::same_file(t, p))
    {
        anyhow::bail!("--truck-out and --plot name one file, {}", t.display());
    }
    let truck_to_stdout = a
        .truck_out
        .as_deref()
        .is_some_and(forkbench_core::files::is_stdout);
    if truck_to_stdout && a.json {
        anyhow::bail!("--json and --truck-out - both print to standard output; give one a file");
    }
    // A rosbag2 directory (its metadata.yaml and .mcap parts) is read as MCAP, as detect
    // reads it.
    let is_mcap = a.log.is_dir()
        || a.log
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("mcap"));
    let log = if is_mcap {
        let fields: [String; 5] = a
            .fields
            .clone()
            .try_into()
            .map_err(|_| anyhow::anyhow!("--fields takes 5 names"))?;
        forkbench_identify::mcap_log::read_mcap(&a.log, &a.topic, &fields)?
    } else {
        forkbench_identify::read_csv(&a.log)?
    };
    let fit = forkbench_identify::identify(&log)
        .with_context(|| format!("identifying {}", a.log.display()))?;
    if let Some(out) = &a.truck_out {
        forkbench_core::files::write_atomic(out, fit.truck_toml().as_bytes())
            .with_context(|| format!("writing {}", out.display()))?;
    }
    if let Some(plot) = &a.plot {
        forkbench_report::identify::draw(plot, &fit)?;
    }
    // With `--truck-out -` standard output is the truck file: the report goes to stderr.
    if truck_to_stdout {
        eprint!("{}", fit.text());
        return Ok(());
    }
    if a.json {
        return crate::emit_json_line(&fit);
    }
    crate::emit(&fit.text())
}

/// `forkbench step-test`: drive the simulated truck through seeded steering and speed
/// steps and write the actuator log `identify` reads.
#[derive(Debug, clap::Args)]
pub struct StepTestArgs {
    /// The truck driven: a preset of actuators, or a truck file (a whole truck from
    /// `trucks/`, or some of its keys over the A30's).
    #[arg(long, value_name = "PRESET|FILE")]
    truck: Option<String>,
    /// Where the CSV log goes.
    #[arg(long)]
    out: std::path::PathBuf,
    /// Runs (each from rest), 1–1000.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=1000))]
    runs: u32,
    /// Length of each run in seconds, 2–600.
    #[arg(long, default_value_t = 20.0)]
    run_s: f64,
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

pub fn step_test(a: &StepTestArgs) -> anyhow::Result<()> {
    use anyhow::Context as _;
    if !(a.run_s.is_finite() && (2.0..=600.0).contains(&a.run_s)) {
        anyhow::bail!("--run-s {}: must lie within 2–600 s", a.run_s);
    }
    if let Some(t) = &a.truck
        && forkbench_core::files::same_file(std::path::Path::new(t), &a.out)
    {
        anyhow::bail!(
            "--out {}: is the --truck file itself; writing the log there would destroy it",
            a.out.display()
        );
    }
    let (preset, settings) = truck_settings(a.truck.as_deref())?;
    let truck = forkbench_trial::trial::apply_truck(
        &forkbench_core::ForkliftSpec::default(),
        preset.as_deref(),
        &settings,
    )?;
    let sim = forkbench_sim::SimConfig::default();
    truck.control.steps_per_tick(sim.dt_s)?;
    let test = forkbench_identify::excite::StepTest {
        runs: a.runs as usize,
        run_s: a.run_s,
        seed: a.seed,
        steering: true,
    };
    let log = forkbench_identify::excite::step_test(&truck, &sim, &test)?;
    forkbench_core::files::write_atomic(&a.out, forkbench_identify::to_csv(&log).as_bytes())
        .with_context(|| format!("writing {}", a.out.display()))?;
    let status = format!(
        "{} runs of {} s written to {}\n",
        a.runs,
        a.run_s,
        a.out.display()
    );
    // With `--out -` standard output is the CSV: the status line goes to standard error.
    if forkbench_core::files::is_stdout(&a.out) {
        eprint!("{status}");
        return Ok(());
    }
    crate::emit(&status)
}
