//! The breadth-first search over body-centre cells × heading layers.

use std::collections::VecDeque;

use super::{Mode, ROOT, Reached, Space};

impl Space {
    /// Breadth-first search from leg 1 (`forward`) or back from leg 2; stops at the first
    /// goal when `stop_at_goal`.
    pub fn search(&self, forward: bool, stop_at_goal: bool) -> Reached {
        let n = self.cells() * self.layers;
        let mut parent = vec![0u32; n];
        let mut pos = vec![[0.0f64; 2]; n];
        let mut queue = VecDeque::new();
        // A queued state not yet expanded takes a later arrival nearer its cell's centre.
        let mut expanded = vec![false; n];
        let (first, last) = (0, self.layers - 1);
        let start_layer = if forward { first } else { last };
        self.seed(forward, start_layer, &mut parent, &mut pos, &mut queue);
        let mut goal = None;
        let mut moves: Vec<([f64; 2], usize)> = Vec::with_capacity(10);
        while let Some(s) = queue.pop_front() {
            let s = s as usize;
            expanded[s] = true;
            let (layer, p) = (s / self.cells(), pos[s]);
            let done = if forward {
                layer == last && self.is_goal(p)
            } else {
                layer == first && self.is_start(p)
            };
            if done {
                goal = Some(s as u32);
                if stop_at_goal {
                    break;
                }
            }
            let here = self.body(p, layer);
            moves.clear();
            self.moves_from((p, layer), forward, stop_at_goal, &parent, &mut moves);
            for &(q, ql) in &moves {
                if !self.in_window(q) {
                    continue;
                }
                let Some(cell) = self.cell_of(q) else {
                    continue;
                };
                let t = ql * self.cells() + cell;
                let seen = parent[t] != 0;
                // The pose a state keeps decides what follows, above all for the truck,
                // which cannot slide: keeping the first arrival made its W_min jump by
                // several cells under 1e-7 m changes. Preferring the arrival nearest the
                // cell centre (until the state is expanded) ties the choice to the grid,
                // not to the order of arrival; each kept move is still checked exactly.
                let better = seen && !expanded[t] && {
                    let c = self.cell_centre(cell);
                    let d = |p: [f64; 2]| (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2);
                    d(q) < d(pos[t])
                };
                if (seen && !better) || !self.free_to(&here, q, ql) {
                    continue;
                }
                parent[t] = s as u32 + 1;
                pos[t] = q;
                if !seen {
                    queue.push_back(t as u32);
                }
            }
        }
        Reached { parent, pos, goal }
    }

    /// Queues the free states of the search's first leg as roots.
    fn seed(
        &self,
        forward: bool,
        start_layer: usize,
        parent: &mut [u32],
        pos: &mut [[f64; 2]],
        queue: &mut VecDeque<u32>,
    ) {
        for cell in 0..self.cells() {
            let p = self.cell_centre(cell);
            let starts = if forward {
                self.is_start(p)
            } else {
                self.is_goal(p)
            };
            if starts
                && self.in_window(p)
                && self.free_to(&self.body(p, start_layer), p, start_layer)
            {
                let s = start_layer * self.cells() + cell;
                parent[s] = ROOT;
                pos[s] = p;
                queue.push_back(s as u32);
            }
        }
    }

    /// The moves out of state (`p`, `layer`): lattice steps and slides where the mode
    /// translates, straight drives, and turns to the next layer.
    fn moves_from(
        &self,
        (p, layer): ([f64; 2], usize),
        forward: bool,
        stop_at_goal: bool,
        parent: &[u32],
        moves: &mut Vec<([f64; 2], usize)>,
    ) {
        let h = self.res.cell_m;
        let sign = if forward { 1.0 } else { -1.0 };
        let head = self.heading(layer);
        let (first, last) = (0, self.layers - 1);
        if self.translates(layer) {
            for (dx, dy) in [
                (1, 0),
                (-1, 0),
                (0, 1),
                (0, -1),
                (1, 1),
                (1, -1),
                (-1, 1),
                (-1, -1),
            ] {
                moves.push(([p[0] + dx as f64 * h, p[1] + dy as f64 * h], layer));
            }
            // Slides along leg 2 itself: lattice steps alone need a channel about a
            // cell wider than the body to zigzag along an oblique leg.
            let d2 = self.bend.d2;
            for dir in [d2, [-d2[0], -d2[1]]] {
                moves.push((self.straight_step(p, dir), layer));
            }
        }
        if self.drives_straight(layer) {
            let dir = [sign * head.cos(), sign * head.sin()];
            let q = self.straight_step(p, dir);
            moves.push((q, layer));
            if self.mode == Mode::Truck && !stop_at_goal {
                // A truck cannot slide back onto a ray whose cells other poses took
                // over: for the whole reachable set (G regions) it also drives on
                // through cells already reached to the first one that is not (one
                // sweep covers the stretch: a translation's hull). Without it the
                // truck's G missed strips along the walls up to 4 cells wide; a search
                // for one passage (W_min) skips it, at 2.5× the time it moves W_min by
                // under a cell.
                // (Cells outside the corridor are never reached, so the walk stops
                // at a wall; the move's own checks then drop it.)
                let mut far = q;
                let layer_base = layer * self.cells();
                while self
                    .cell_of(far)
                    .is_some_and(|c| parent[layer_base + c] != 0)
                {
                    far = self.straight_step(far, dir);
                }
                if far != q {
                    moves.push((far, layer));
                }
            }
        }
        for &r in &self.turn_radii_m {
            if forward && layer < last {
                let d = self.turn_displacement(layer, r);
                moves.push(([p[0] + d[0], p[1] + d[1]], layer + 1));
            }
            if !forward && layer > first {
                let d = self.turn_displacement(layer - 1, r);
                moves.push(([p[0] - d[0], p[1] - d[1]], layer - 1));
            }
        }
    }
}
