//! The viewer layout (blueprint) and the fixed colours every recording uses.

use rerun::blueprint::components::{PanelState, PlayState};
use rerun::blueprint::{
    Blueprint, BlueprintPanel, Horizontal, SelectionPanel, Spatial2DView, Tabs, TextDocumentView,
    TimePanel, TimeSeriesView, Vertical,
};

/// Colours are fixed here, not assigned by the viewer, so every recording reads alike.
pub(super) const TRUCK_RGB: [u8; 3] = [230, 190, 25];
pub(super) const PALLET_RGB: [u8; 3] = [205, 140, 50];
pub(super) const PALLET_INITIAL_RGBA: [u8; 4] = [205, 140, 50, 90];
pub(super) const ESTIMATE_RGB: [u8; 3] = [220, 40, 40];
pub(super) const RACK_RGB: [u8; 3] = [150, 150, 150];
pub(super) const GRID_RGBA: [u8; 4] = [120, 120, 120, 70];
pub(super) const PLAN_RGB: [u8; 3] = [40, 110, 240];
pub(super) const SUPERSEDED_RGBA: [u8; 4] = [40, 110, 240, 60];
pub(super) const CONTROL_RGB: [u8; 3] = [120, 150, 230];
pub(super) const TRAJECTORY_RGB: [u8; 3] = [40, 200, 80];
pub(super) const LOOKAHEAD_RGB: [u8; 3] = [235, 60, 220];
pub(super) const START_RGB: [u8; 3] = [240, 240, 240];
pub(super) const GOAL_RGB: [u8; 3] = [80, 170, 255];
/// True (green) and measured (red) pose at a NAV350 fix.
pub(super) const TRUE_RGB: [u8; 3] = [40, 200, 80];
pub(super) const MEASURED_RGB: [u8; 3] = [240, 70, 70];
/// Actual (drawn first, wide) and command (on top, narrow) of a plotted quantity; limits.
pub(super) const COMMAND_RGB: [u8; 3] = [255, 170, 40];
pub(super) const ACTUAL_RGB: [u8; 3] = [70, 160, 255];
pub(super) const LIMIT_RGB: [u8; 3] = [235, 60, 60];

/// Draw order in the map (higher on top): the driven trajectory over the plans.
pub(super) const ORDER_GRID: f32 = 0.0;
pub(super) const ORDER_WORLD: f32 = 1.0;
pub(super) const ORDER_PLAN: f32 = 2.0;
pub(super) const ORDER_TRUCK: f32 = 3.0;
pub(super) const ORDER_TRAJECTORY: f32 = 4.0;
pub(super) const ORDER_MARKERS: f32 = 5.0;

/// The entry-error plots cover the fork tips' last this many metres before the pallet face,
/// then the insertion.
pub(super) const APPROACH_M: f64 = 1.5;

/// A plot: its entity, title and series (name, colour); several series share one entity,
/// so one chunk.
pub(super) struct Plot {
    pub entity: &'static str,
    pub title: &'static str,
    pub series: &'static [(&'static str, [u8; 3])],
}

/// Entry errors first: they decide the verdict, and the limits are drawn beside them. They
/// are plotted over the approach only (see [`APPROACH_M`]), where the limits apply and the
/// axis range shows centimetres.
pub(super) const PLOTS: [Plot; 5] = [
    Plot {
        entity: "plots/lateral_error",
        title: "entry: lateral offset to pallet axis (m)",
        series: &[
            ("fork root", ACTUAL_RGB),
            ("+ limit", LIMIT_RGB),
            ("− limit", LIMIT_RGB),
        ],
    },
    Plot {
        entity: "plots/heading_error",
        title: "entry: heading to pallet axis (°)",
        series: &[
            ("truck", ACTUAL_RGB),
            ("+ limit", LIMIT_RGB),
            ("− limit", LIMIT_RGB),
        ],
    },
    Plot {
        entity: "plots/steering",
        title: "steering (rad)",
        series: &[("actual", ACTUAL_RGB), ("command", COMMAND_RGB)],
    },
    Plot {
        entity: "plots/speed",
        title: "speed (m/s)",
        series: &[("actual", ACTUAL_RGB), ("command", COMMAND_RGB)],
    },
    Plot {
        entity: "plots/contact_force",
        title: "fork contact force (N)",
        series: &[("contact", ACTUAL_RGB), ("limit", LIMIT_RGB)],
    },
];

fn plot_view(p: &Plot) -> TimeSeriesView {
    TimeSeriesView::new(p.title).with_origin(p.entity)
}

/// Map on the left; on the right the verdict (with the event log) and two tab groups of
/// tall plots: entry errors, then the drive. Every view costs the file two chunks, so the
/// event log is part of the verdict document rather than a view of its own.
/// Which plot a layout opens first in its tab group: the failed quantity's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Focus {
    Lateral,
    Heading,
    ContactForce,
}

impl Focus {
    pub(super) const ALL: [Focus; 3] = [Focus::Lateral, Focus::Heading, Focus::ContactForce];

    /// The plot that shows why a trial failed on `failure`, when one does.
    pub(super) fn of(failure: Option<&forkbench_trial::Failure>) -> Option<Focus> {
        use forkbench_trial::Failure as F;
        match failure? {
            F::LateralError | F::ForkOutsidePocket => Some(Focus::Lateral),
            F::HeadingError => Some(Focus::Heading),
            F::ContactForce | F::PalletDisplaced => Some(Focus::ContactForce),
            _ => None,
        }
    }
}

pub(super) fn blueprint(focus: Focus) -> Blueprint {
    let first = |i: usize, j: usize| {
        if focus == Focus::Heading {
            [j, i]
        } else {
            [i, j]
        }
    };
    let errors = Tabs::new(first(0, 1).map(|k| plot_view(&PLOTS[k]).into()));
    let drive_order: [usize; 3] = if focus == Focus::ContactForce {
        [4, 2, 3]
    } else {
        [2, 3, 4]
    };
    // Scalars any component sends (`Recorder::signal`) share the last tab.
    let signals = TimeSeriesView::new("other signals").with_origin("signals");
    // Localisation: the controller's pose error and each fix's quality (metres), and how
    // many reflectors the NAV350 used (0: no fix).
    let localisation = TimeSeriesView::new("localisation (m)").with_origin("signals/localisation");
    let reflectors = TimeSeriesView::new("NAV350 reflectors used").with_origin("signals/nav350");
    let drive = Tabs::new(
        drive_order
            .map(|k| plot_view(&PLOTS[k]).into())
            .into_iter()
            .chain([localisation.into(), reflectors.into(), signals.into()]),
    );
    let right = Vertical::new([
        TextDocumentView::new("verdict")
            .with_origin("verdict")
            .into(),
        errors.into(),
        drive.into(),
    ])
    .with_row_shares([2.4, 1.0, 1.0]);
    Blueprint::new(
        Horizontal::new([
            Spatial2DView::new("map (y up, 1 m grid)")
                .with_origin("/")
                // A mission's roadmap swamps its route: hidden, one click away in the
                // blueprint panel.
                .with_contents(["+ map/**", "- map/nav/roadmap"])
                .into(),
            right.into(),
        ])
        .with_column_shares([0.55, 0.45]),
    )
    .with_auto_views(false)
    // The views get the whole window; the panels open with a click.
    .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed))
    .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
    // A finished recording opens at its end, where the verdict was made.
    .with_time_panel(
        TimePanel::new()
            .with_timeline("sim_time")
            .with_play_state(PlayState::Following),
    )
}
