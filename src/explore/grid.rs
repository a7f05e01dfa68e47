//! The local strategy's implicit uniform grid over the workspace (Sec. III-A).
//!
//! "Each time the sensor makes contact with the unknown object and a measurement is taken, the location
//! ℓ of the sensor is added to the corresponding grid cell. [...] a cell c is then selected with
//! probability inversely proportional to the number of measurements taken from locations inside that
//! cell. [...] The planner then selects a location ℓ uniformly at random from all the locations
//! associated with c and samples a target position p uniformly at random inside a small sphere
//! centered at ℓ."
//!
//! Cells exist only once a location falls in them (a hash map keyed by integer cell coordinates), so
//! the grid costs nothing where nothing was read. Cells are kept in first-visit order, which makes the
//! choice deterministic for a given seed.

use std::collections::HashMap;

use glam::{DVec3, IVec3};
use rand::RngExt;

use crate::rng::Rng;

/// Reading locations binned into cubic cells.
#[derive(Debug, Clone)]
pub struct ReadingGrid {
    origin_m: DVec3,
    cell_m: f64,
    index: HashMap<IVec3, usize>,
    cells: Vec<Vec<DVec3>>,
}

impl ReadingGrid {
    /// A grid of cubes of side `cell_m` anchored at `origin_m` (the workspace's lower corner).
    pub fn new(origin_m: DVec3, cell_m: f64) -> Self {
        Self {
            origin_m,
            cell_m,
            index: HashMap::new(),
            cells: Vec::new(),
        }
    }

    fn cell_of(&self, p: DVec3) -> IVec3 {
        ((p - self.origin_m) / self.cell_m).floor().as_ivec3()
    }

    /// Records a reading location.
    pub fn add(&mut self, location_m: DVec3) {
        let key = self.cell_of(location_m);
        let next = self.cells.len();
        let slot = *self.index.entry(key).or_insert(next);
        if slot == next {
            self.cells.push(Vec::new());
        }
        self.cells[slot].push(location_m);
    }

    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// Non-empty cells, in first-visit order, with their locations.
    pub fn cells(&self) -> &[Vec<DVec3>] {
        &self.cells
    }

    /// Index of a non-empty cell chosen with probability ∝ 1 / (its number of locations).
    pub fn choose_cell(&self, rng: &mut Rng) -> Option<usize> {
        let total: f64 = self.cells.iter().map(|c| 1.0 / c.len() as f64).sum();
        if self.cells.is_empty() {
            return None;
        }
        let mut u = rng.random_range(0.0..total);
        for (i, cell) in self.cells.iter().enumerate() {
            u -= 1.0 / cell.len() as f64;
            if u < 0.0 {
                return Some(i);
            }
        }
        Some(self.cells.len() - 1)
    }

    /// The local strategy's target: a cell by inverse count, a location in it uniformly, then a point
    /// uniform in the ball of radius `radius_m` around that location.
    pub fn local_target(&self, radius_m: f64, rng: &mut Rng) -> Option<DVec3> {
        let cell = &self.cells[self.choose_cell(rng)?];
        let location = cell[rng.random_range(0..cell.len())];
        Some(location + uniform_in_ball(radius_m, rng))
    }
}

/// A point uniform in the ball of radius `r` about the origin (rejection from the cube).
pub fn uniform_in_ball(r: f64, rng: &mut Rng) -> DVec3 {
    loop {
        let p = DVec3::new(
            rng.random_range(-1.0..=1.0),
            rng.random_range(-1.0..=1.0),
            rng.random_range(-1.0..=1.0),
        );
        if p.length_squared() <= 1.0 {
            return p * r;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng;

    /// Cells holding 1, 2, 4 and 8 locations are chosen in proportion 8:4:2:1 (chi-square, 3 degrees
    /// of freedom, below the 0.1% critical value 16.27).
    #[test]
    fn cells_are_chosen_inversely_to_their_count() {
        let mut grid = ReadingGrid::new(DVec3::ZERO, 0.01);
        for (cell, count) in [(0, 1), (1, 2), (2, 4), (3, 8)] {
            for k in 0..count {
                grid.add(DVec3::new(cell as f64 * 0.01 + 0.005, 0.005, 0.001 * k as f64));
            }
        }
        assert_eq!(grid.cells().len(), 4);
        let mut r = rng::rng(99);
        let n = 30_000;
        let mut counts = [0usize; 4];
        for _ in 0..n {
            counts[grid.choose_cell(&mut r).unwrap()] += 1;
        }
        let weights = [8.0, 4.0, 2.0, 1.0];
        let chi2: f64 = counts
            .iter()
            .zip(weights)
            .map(|(&c, w)| {
                let e = n as f64 * w / 15.0;
                (c as f64 - e).powi(2) / e
            })
            .sum();
        assert!(chi2 < 16.27, "chi2 = {chi2}, counts {counts:?}");
    }

    #[test]
    fn local_targets_lie_in_the_ball_around_a_location() {
        let mut grid = ReadingGrid::new(DVec3::splat(-1.0), 0.05);
        let locations = [DVec3::new(0.1, 0.0, 0.2), DVec3::new(-0.3, 0.2, 0.0)];
        for l in locations {
            grid.add(l);
        }
        let mut r = rng::rng(4);
        for _ in 0..1000 {
            let p = grid.local_target(0.02, &mut r).unwrap();
            assert!(locations.iter().any(|l| (p - *l).length() <= 0.02 + 1e-12));
        }
        assert!(
            ReadingGrid::new(DVec3::ZERO, 0.1)
                .local_target(0.02, &mut r)
                .is_none()
        );
    }
}
