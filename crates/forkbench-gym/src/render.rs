//! A top-down picture of an episode (racks, plan, pallet, estimate, truck and forks, scan returns) as RGB pixels, for `render_mode="rgb_array"`.

use forkbench_core::{ForkliftSpec, PalletSpec, Pose2};
use forkbench_trial::trial::SceneView;
use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

/// The map square an episode is drawn in: fixed per episode, so a video does not pan.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Window {
    centre: [f64; 2],
    half_m: f64,
}

impl Window {
    /// A square around the truck's start and the pallet, with room to manoeuvre.
    pub(crate) fn around(start: &Pose2, pallet: &Pose2) -> Self {
        let centre = [
            (start.x_m + pallet.x_m) / 2.0,
            (start.y_m + pallet.y_m) / 2.0,
        ];
        let half_m = (start.distance_to(pallet) / 2.0 + 3.0).max(4.0);
        Window { centre, half_m }
    }
}

/// Map to pixels: y up, the window's square fitted into the image.
struct Frame {
    window: Window,
    scale: f64,
    size: [f64; 2],
}

impl Frame {
    fn px(&self, p: [f64; 2]) -> (f32, f32) {
        let x = (p[0] - self.window.centre[0]) * self.scale + self.size[0] / 2.0;
        let y = self.size[1] / 2.0 - (p[1] - self.window.centre[1]) * self.scale;
        (x as f32, y as f32)
    }

    fn polyline(&self, points: &[[f64; 2]], close: bool) -> Option<tiny_skia::Path> {
        let mut pb = PathBuilder::new();
        let (first, rest) = points.split_first()?;
        let (x, y) = self.px(*first);
        pb.move_to(x, y);
        for p in rest {
            let (x, y) = self.px(*p);
            pb.line_to(x, y);
        }
        if close {
            pb.close();
        }
        pb.finish()
    }
}

fn paint(rgba: [u8; 4]) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color(Color::from_rgba8(rgba[0], rgba[1], rgba[2], rgba[3]));
    p.anti_alias = true;
    p
}

/// Fills (and outlines, when `line` is given) each closed outline.
fn shapes(
    pm: &mut Pixmap,
    f: &Frame,
    outlines: &[[[f64; 2]; 5]],
    fill: [u8; 4],
    line: Option<[u8; 4]>,
) {
    let stroke = Stroke {
        width: 1.5,
        ..Stroke::default()
    };
    for o in outlines {
        let Some(path) = f.polyline(&o[..4], true) else {
            continue;
        };
        if fill[3] > 0 {
            pm.fill_path(
                &path,
                &paint(fill),
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
        if let Some(c) = line {
            pm.stroke_path(&path, &paint(c), &stroke, Transform::identity(), None);
        }
    }
}

/// The scene drawn into a `width` × `height` RGB image (row-major, 3 bytes a pixel).
pub(crate) fn draw(
    view: &SceneView,
    truck: &ForkliftSpec,
    pallet: &PalletSpec,
    window: Window,
    [width, height]: [u32; 2],
) -> Vec<u8> {
    let Some(mut pm) = Pixmap::new(width, height) else {
        return vec![0; width as usize * height as usize * 3];
    };
    pm.fill(Color::from_rgba8(245, 245, 240, 255));
    let f = Frame {
        window,
        scale: f64::from(width.min(height)) / (2.0 * window.half_m),
        size: [f64::from(width), f64::from(height)],
    };
    shapes(&mut pm, &f, &view.obstacles, [110, 110, 120, 255], None);
    if let Some(path) = f.polyline(&view.path, false) {
        let stroke = Stroke {
            width: 2.0,
            ..Stroke::default()
        };
        pm.stroke_path(
            &path,
            &paint([40, 110, 220, 255]),
            &stroke,
            Transform::identity(),
            None,
        );
    }
    shapes(
        &mut pm,
        &f,
        &pallet.outlines(&view.pallet),
        [150, 100, 50, 255],
        None,
    );
    shapes(
        &mut pm,
        &f,
        &pallet.outlines(&view.pallet_estimate),
        [0, 0, 0, 0],
        Some([220, 40, 40, 255]),
    );
    let truck_shapes = truck.outlines(&view.fork_root);
    shapes(
        &mut pm,
        &f,
        &truck_shapes[..1],
        [240, 190, 40, 255],
        Some([60, 50, 20, 255]),
    );
    shapes(&mut pm, &f, &truck_shapes[1..], [90, 90, 90, 255], None);
    let dot = paint([200, 0, 160, 255]);
    for p in &view.scan {
        let (x, y) = f.px(*p);
        if let Some(r) = Rect::from_xywh(x - 1.0, y - 1.0, 2.5, 2.5) {
            pm.fill_rect(r, &dot, Transform::identity(), None);
        }
    }
    // The pixmap is premultiplied RGBA on an opaque background: drop alpha.
    pm.data()
        .chunks_exact(4)
        .flat_map(|px| [px[0], px[1], px[2]])
        .collect()
}
