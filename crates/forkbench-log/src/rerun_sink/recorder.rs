//! What the trial reports, turned into rerun entities: scene, plans, steps, events and the verdict.

use forkbench_core::Pose2;
use forkbench_core::units::wrap_angle;
use forkbench_trial::{Level, Limits, Recorder, SceneInfo, StepRecord, TrialOutcome};

use super::RerunRecorder;
use super::columns::{color, rgba, strip};
use super::layout::*;
use super::scene::pose_arrow;
use crate::{pallet_outlines, truck_outlines};

/// Limits thin, commands narrower than the actual values they are drawn over.
fn series_width(name: &str) -> f32 {
    match name {
        n if n.contains("limit") => 1.0,
        "command" | "planned" => 1.5,
        _ => 2.5,
    }
}

/// A path's samples as a strip.
fn strip_of(path: &forkbench_core::Path) -> Vec<[f32; 2]> {
    path.samples
        .iter()
        .map(|p| [p.x_m as f32, p.y_m as f32])
        .collect()
}

/// A mission's legs as a markdown table (empty for a pick trial).
fn legs_table(o: &TrialOutcome) -> String {
    if o.legs.is_empty() {
        return String::new();
    }
    let mut s = String::from(
        "| leg | done | planned | clearance | cross-track max | time |\n|---|---|---|---|---|---|\n",
    );
    for l in &o.legs {
        s += &format!(
            "| {} | {} | {:.1} m | {:.2} m | {:.0} mm | {:.1} s |\n",
            l.name,
            if l.success { "yes" } else { "**no**" },
            l.planned_length_m,
            l.min_clearance_m,
            1e3 * l.cross_track_max_m,
            l.time_s
        );
    }
    s + "\n"
}

/// The pick's criteria that keep a measurement, each as a row of the verdict's table
/// (`criterion | value | limit`), the broken ones in bold.
fn criteria_rows(o: &TrialOutcome, tol: &Limits) -> String {
    forkbench_trial::trial::PICK_CRITERIA
        .iter()
        .filter_map(|c| {
            let r = c.reading(o, tol)?;
            let value = if o.broke(&c.failure) {
                format!("**{}** ❌", r.value)
            } else {
                r.value
            };
            Some(format!("| {} | {value} | {} |\n", r.label, r.limit))
        })
        .collect()
}

/// The step criteria's measurements as rows of the verdict's table (`measure | value`).
fn measures_rows(o: &TrialOutcome) -> String {
    o.measures
        .iter()
        .map(|(k, v)| format!("| {} | {v:.1} | |\n", k.replace('_', " ")))
        .collect()
}

/// The handling cycle's phases: each one's verdict, time, distance and load.
fn phases_table(o: &TrialOutcome) -> String {
    if o.phases.is_empty() {
        return String::new();
    }
    let mut s =
        String::from("| phase | verdict | time | distance | load |\n|---|---|---|---|---|\n");
    for p in &o.phases {
        let verdict = match (p.success, &p.failure) {
            (true, _) => "✅ done".to_owned(),
            (false, f) => format!("❌ **{}**", f.as_ref().map_or("unknown", |f| f.name())),
        };
        s += &format!(
            "| {} | {verdict} | {:.1} s | {:.2} m | {} |\n",
            p.name,
            p.time_s,
            p.distance_m,
            if p.loaded { "on the forks" } else { "—" }
        );
    }
    s + "\n"
}

impl RerunRecorder {
    /// Fixed styles and series names, sent with each entity's first columns.
    fn styles(&mut self) {
        for plot in &PLOTS {
            let lines = rerun::SeriesLines::new()
                .with_names(plot.series.iter().map(|(n, _)| *n))
                .with_colors(plot.series.iter().map(|(_, c)| color(*c)))
                .with_widths(plot.series.iter().map(|(n, _)| series_width(n)));
            // Static: a plot showing a late time window (a mission's pick) still finds
            // its names, which a first-row value outside the window would not give.
            let r = self.rec.log_static(plot.entity, &lines);
            self.note(r);
        }
        let trajectory = rerun::LineStrips2D::update_fields()
            .with_colors([color(TRAJECTORY_RGB)])
            .with_radii([0.02])
            .with_draw_order(ORDER_TRAJECTORY);
        self.set_once("map/track/trajectory", &trajectory);
        // The trajectory's tail and the look-ahead point share the entity of "now".
        let lookahead = rerun::Points2D::update_fields()
            .with_colors([color(LOOKAHEAD_RGB)])
            .with_radii([0.07])
            .with_draw_order(ORDER_MARKERS);
        self.set_once("map/track/now", &trajectory);
        self.set_once("map/track/now", &lookahead);
        let fixes = rerun::Arrows2D::update_fields()
            .with_radii([0.02])
            .with_draw_order(ORDER_MARKERS);
        self.set_once("map/sensors/nav350_fix", &fixes);
    }

    /// Notes where and when the fork tips first reach the face plane within the pallet's
    /// width; the markers go out with the outcome, carrying the judge's own numbers.
    fn mark_entry(&mut self, s: &StepRecord, local: &Pose2) {
        let [fork_length_m, half_width_m] = self.entry_geometry;
        if self.entry_at.is_some()
            || local.x_m + fork_length_m < 0.0
            || local.y_m.abs() >= half_width_m
        {
            return;
        }
        self.entry_at = Some((s.t_s, [s.truth.x_m, s.truth.y_m]));
    }

    /// The judged entry on both entry plots and, labelled, on the map.
    fn draw_entry(&mut self, o: &TrialOutcome) {
        let (Some((t_s, at)), Some(lateral), Some(heading)) =
            (self.entry_at, o.lateral_error_m, o.heading_error_rad)
        else {
            return;
        };
        let heading_deg = heading.to_degrees();
        for (plot, v) in [
            ("plots/lateral_error/entry", lateral),
            ("plots/heading_error/entry", heading_deg),
        ] {
            let style = rerun::SeriesPoints::new()
                .with_names(["fork entry (judged)"])
                .with_colors([color(START_RGB)])
                .with_marker_sizes([9.0]);
            let r = self.rec.log_static(plot, &style);
            self.note(r);
            self.at(t_s);
            let r = self.rec.log(plot, &rerun::Scalars::single(v));
            self.note(r);
        }
        let point = rerun::Points2D::new([[at[0] as f32, at[1] as f32]])
            .with_colors([color(START_RGB)])
            .with_radii([0.06])
            .with_labels([format!("fork entry: {lateral:.3} m, {heading_deg:.2}°")])
            .with_draw_order(ORDER_MARKERS);
        let r = self.rec.log("map/track/entry", &point);
        self.note(r);
    }

    /// The verdict view's text: the outcome first, then what the map's colours mean.
    fn verdict_text(&self, o: &TrialOutcome) -> String {
        let failure = o.failure.as_ref().map_or("unknown", |f| f.name());
        let head = if o.success {
            "#### ✅ SUCCESS".to_owned()
        } else {
            format!("#### ❌ FAILED: {failure}")
        };
        let detail = verdict_detail(o);
        format!(
            "{head}\n\n{detail}\n\n{}\
             | criterion | value | limit |\n|---|---|---|\n{}{}\n\
             {}**{}** · case `{}` · planner `{}` · tracker `{}` · seed {} · {:.2} s simulated, {} replans\n\n\
             Map (y up, 1 m grid): white arrow start · light-blue arrow goal (pre-entry) · \
             blue plan being driven (thin: its control polygon), faded plans superseded · \
             green driven trajectory · \
             magenta look-ahead · yellow truck · orange (wide) pallet, faint where it stood · \
             red (thin, on top) pallet estimate · green/red arrows true/measured NAV350 fix · \
             white dots NAV350 reflectors, red ones missing, green rays to those the current \
             fix used · mission legs: grey blocked cells, orange A* polyline, purple backing \
             out (the PRM roadmap is hidden: add map/nav/roadmap in the blueprint panel) · \
             with people: pink people, the protective field green when clear, red when broken \
             or stopping, the warning field yellow\n\n\
             **Events**\n\n```text\n{}\n```\n\n\
             **Outcome**\n\n```json\n{}\n```\n",
            phases_table(o),
            criteria_rows(o, self.tolerances.as_ref().unwrap_or(&Limits::default())),
            measures_rows(o),
            legs_table(o),
            o.scenario,
            o.case,
            o.planner,
            o.tracker,
            o.seed,
            o.sim_time_s,
            o.replans,
            self.events.join("\n"),
            serde_json::to_string_pretty(o).unwrap_or_default(),
        )
    }

    fn log_verdict(&mut self, markdown: String) {
        let doc = rerun::TextDocument::new(markdown).with_media_type(rerun::MediaType::markdown());
        let r = self.rec.log_static("verdict", &doc);
        self.note(r);
    }
}

impl Recorder for RerunRecorder {
    fn scene(&mut self, s: &SceneInfo<'_>) {
        self.tolerances = Some(s.tolerances.clone());
        self.entry_geometry = [s.truck.fork_length_m, s.pallet.width_m / 2.0];
        let name = format!(
            "{} / {} / {} / {} / seed {}",
            s.scenario, s.case, s.planner, s.tracker, s.seed
        );
        let r = self.rec.send_recording_name(name.clone());
        self.note(r);
        self.at(0.0);
        let r = self.rec.log(
            "events",
            &rerun::TextLog::new(format!("trial {name}")).with_level(rerun::TextLogLevel::INFO),
        );
        self.note(r);
        self.draw_scene(s);
        self.styles();
        let origin = Pose2::new(0.0, 0.0, 0.0);
        // The true pallet wide and beneath, the estimate thin and on top: where they
        // overlap both stay visible.
        self.local_outlines(
            "map/world/pallet",
            &pallet_outlines(s.pallet, &origin),
            (PALLET_RGB, 0.04, ORDER_TRUCK - 0.5),
        );
        self.local_outlines(
            "map/sensors/pallet_estimate",
            &pallet_outlines(s.pallet, &origin),
            (ESTIMATE_RGB, 0.01, ORDER_TRUCK + 0.5),
        );
        let truck = truck_outlines(s.truck, &origin);
        self.local_outlines("map/truck", &truck, (TRUCK_RGB, 0.015, ORDER_TRUCK));
        // The start pose and the pallet's first pose go out with the first columns.
        self.cols.truck_start = Some(s.start);
        self.cols.pallet_pose.0.push(0.0);
        self.cols.pallet_pose.1.push(s.pallet_pose);
        self.cols.last_pallet = Some(s.pallet_pose);
    }

    fn plan(
        &mut self,
        t_s: f64,
        index: u32,
        path: &forkbench_core::Path,
        control_polygon: Option<&[[f64; 2]]>,
    ) {
        self.at(t_s);
        // The plan driven so far fades: only the new one is drawn bright.
        if self.plans > 0 {
            let faded = [rgba(SUPERSEDED_RGBA)];
            let lines = rerun::LineStrips2D::update_fields().with_colors(faded);
            let points = rerun::Points2D::update_fields().with_colors(faded);
            let goal = rerun::Arrows2D::update_fields().with_colors(faded);
            let r = self.rec.log(
                format!("map/plan/{}", self.plans - 1),
                &[&lines as &dyn rerun::AsComponents, &points, &goal],
            );
            self.note(r);
        }
        self.plans = index + 1;
        // Path, control polygon and points, and the goal arrow in one row of one entity:
        // one chunk per plan.
        let mut strips = vec![strip_of(path)];
        let (mut colors, mut radii) = (vec![color(PLAN_RGB)], vec![0.03]);
        if let Some(c) = control_polygon {
            strips.push(strip(c));
            colors.push(color(CONTROL_RGB));
            radii.push(0.008);
        }
        let lines = rerun::LineStrips2D::new(strips)
            .with_colors(colors)
            .with_radii(radii)
            .with_draw_order(ORDER_PLAN);
        let points = rerun::Points2D::new(control_polygon.map(strip).unwrap_or_default())
            .with_radii([0.05])
            .with_colors([color(CONTROL_RGB)])
            .with_draw_order(ORDER_PLAN);
        let end = path.samples.last().map_or(Pose2::new(0.0, 0.0, 0.0), |e| {
            Pose2::new(e.x_m, e.y_m, e.heading_rad)
        });
        let goal = pose_arrow(&end, GOAL_RGB);
        let r = self.rec.log(
            format!("map/plan/{index}"),
            &[&lines as &dyn rerun::AsComponents, &points, &goal],
        );
        self.note(r);
    }

    fn signal(
        &mut self,
        t_s: f64,
        path: &str,
        signal: &forkbench_core::Signal<'_>,
        style: forkbench_core::Style,
    ) {
        self.log_signal(t_s, path, signal, style);
    }

    fn step(&mut self, s: &StepRecord) {
        // Against the pallet where it is now, as the judge measures the entry.
        let local = s.pallet.to_local(&s.truth);
        let heading_deg = wrap_angle(local.heading_rad).to_degrees();
        let [lat, head, contact] = self.tolerances.as_ref().map_or([f64::NAN; 3], |t| {
            [t.lateral_m, t.heading_deg(), t.contact_force_n]
        });
        // The fork tips' last metres before the face, the entry and the insertion.
        let approach = local.x_m + self.entry_geometry[0] >= -APPROACH_M;
        self.mark_entry(s, &local);
        let (lateral, heading): (&[f64], &[f64]) = if approach {
            (&[local.y_m, lat, -lat], &[heading_deg, head, -head])
        } else {
            (&[], &[])
        };
        self.cols.push(
            s,
            [
                lateral,
                heading,
                &[s.steer_rad, s.steer_cmd_rad],
                &[s.speed_mps, s.speed_cmd_mps],
                &[s.contact_force_n, contact],
            ],
        );
        if self.cols.times.len() >= self.send_every {
            self.send_buffered();
        }
    }

    fn event(&mut self, t_s: f64, level: Level, text: &str) {
        self.at(t_s);
        self.events.push(format!("{t_s:7.2} s  {level:?}  {text}"));
        let level = match level {
            Level::Info => rerun::TextLogLevel::INFO,
            Level::Warn => rerun::TextLogLevel::WARN,
            Level::Error => rerun::TextLogLevel::ERROR,
        };
        let r = self
            .rec
            .log("events", &rerun::TextLog::new(text).with_level(level));
        self.note(r);
    }

    fn outcome(&mut self, t_s: f64, outcome: &TrialOutcome) {
        self.draw_entry(outcome);
        self.at(t_s);
        self.cols.whole_strip(t_s);
        let level = if outcome.success {
            rerun::TextLogLevel::INFO
        } else {
            rerun::TextLogLevel::ERROR
        };
        let line = format!("outcome: {}", outcome.verdict_line());
        let r = self
            .rec
            .log("events", &rerun::TextLog::new(line).with_level(level));
        self.note(r);
        let text = self.verdict_text(outcome);
        self.log_verdict(text);
        // A failure opens on the plot of the quantity that failed: a layout with that
        // plot first in its tabs, made the active one.
        let focus = super::layout::Focus::of(outcome.failure.as_ref());
        if let Some(f) = focus.filter(|f| *f != super::layout::Focus::Lateral) {
            match super::blueprint_msgs(f) {
                Ok(msgs) => msgs.iter().for_each(|m| self.rec.record_msg(m.clone())),
                Err(e) => self.note::<(), _>(Err(e)),
            }
        }
        // The outcome is the trial's last call: close now, in parallel with other sinks.
        self.close_async();
    }
}

/// The verdict's first lines: the first failed criterion, the likely cause, then every
/// other one broken, staging and missed looks or fixes: a tight list, so the whole
/// verdict fits its panel.
fn verdict_detail(o: &TrialOutcome) -> String {
    let mut detail = o.failure_detail.clone().unwrap_or_default();
    if let Some(c) = &o.likely_cause {
        detail += &format!("\n- **likely cause:** {c}");
    }
    if !o.also_failed.is_empty() {
        detail += &format!("\n- ❌ **also** {}", o.also_failed.join(" · "));
    }
    if !o.uncertain.is_empty() {
        let drawn: Vec<String> = o
            .uncertain
            .iter()
            .map(|(n, v)| format!("{n} {v:.4}"))
            .collect();
        detail += &format!("\n- **drawn:** {}", drawn.join(" · "));
    }
    if let Some(leg) = o
        .legs
        .iter()
        .find(|l| l.name == forkbench_trial::trial::STAGING_LEG)
    {
        detail += &format!(
            "\n- **staged:** the face was not seen from the start; a {:.1} m manoeuvre ({:.1} m \
             backwards) to look again from the staging pose{}",
            leg.planned_length_m,
            leg.reverse_length_m,
            if leg.success {
                ""
            } else {
                ", and did not reach it"
            }
        );
    }
    if o.estimates_missed > 0 {
        detail += &format!(
            "\n- {} of {} pallet estimates found no pallet (scans under map/sensors)",
            o.estimates_missed, o.estimates
        );
    }
    if o.fixes_missed > 0 {
        detail += &format!(
            "\n- {} NAV350 sweeps gave no pose; largest gap {:.2} s, own pose off by up to {:.3} m",
            o.fixes_missed, o.largest_fix_gap_s, o.localization_error_max_m
        );
    }
    detail
}

#[cfg(test)]
mod tests {
    use forkbench_trial::{Failure, Limits, TrialOutcome};

    /// The verdict's table has a row per pick criterion that keeps its measurement, with
    /// the scenario's limit, and marks the broken ones.
    #[test]
    fn the_verdict_table_comes_from_the_criteria() {
        let mut o = TrialOutcome::blank("s", "c", ("p", "t"), 1, true);
        o.lateral_error_m = Some(0.244);
        o.heading_error_rad = Some(0.01);
        o.max_contact_force_n = 50.0;
        o.insertion_depth_m = 0.0;
        o.fail(Failure::LateralError, "off".into());
        o.also_failed = vec!["insertion_depth: forks 0 m deep".into()];
        let rows = super::criteria_rows(&o, &Limits::default());
        let shown = forkbench_trial::trial::PICK_CRITERIA
            .iter()
            .filter(|c| c.reading(&o, &Limits::default()).is_some())
            .count();
        assert_eq!(rows.lines().count(), shown);
        assert!(
            rows.contains("| lateral offset at entry | **0.244 m** ❌ | 0.1 m |"),
            "{rows}"
        );
        assert!(
            rows.contains("| fork depth | **0.000 m** ❌ | ≥ 1 m |"),
            "{rows}"
        );
        assert!(rows.contains("| heading at entry | 0.57° | 3° |"), "{rows}");
        assert!(rows.contains("| max contact force | 50 N |"), "{rows}");
    }

    /// A trial with uncertain parameters shows what was drawn beside its verdict, so a
    /// searched failure's recording says which parameters it stands for.
    #[test]
    fn the_verdict_names_the_drawn_parameters() {
        let mut o = TrialOutcome::blank("s", "c", ("p", "t"), 1, true);
        o.fail(Failure::LateralError, "off".into());
        assert!(!super::verdict_detail(&o).contains("drawn"));
        o.uncertain
            .insert("steering_time_constant_s".into(), 0.47451);
        o.uncertain.insert("pallet.y_m".into(), -0.012);
        let d = super::verdict_detail(&o);
        assert!(
            d.contains("- **drawn:** pallet.y_m -0.0120 · steering_time_constant_s 0.4745"),
            "{d}"
        );
    }
}
