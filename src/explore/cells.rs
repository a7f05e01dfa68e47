//! Points binned into cubes, for the planner's questions about what lies near a point: the tree
//! vertex nearest a target (`tree`) and the earlier iterations whose targets lay near a candidate
//! (`active`'s touch odds). Both are asked once per planner iteration (the odds once per
//! candidate) of everything the run has recorded, so scanning all of it made a run's cost grow with
//! the square of its iterations.

use std::collections::HashMap;

use glam::{DVec3, IVec3};

/// Items placed at points, binned by point into cubes of `cell_m`, with the bounds of the occupied
/// cells (a ring beyond them holds nothing).
#[derive(Debug, Clone)]
pub(crate) struct PointCells<T> {
    cell_m: f64,
    members: HashMap<IVec3, Vec<T>>,
    /// Items with no cell (a non-finite point, or one beyond 10^6 cells): offered to every search.
    strays: Vec<T>,
    low: IVec3,
    high: IVec3,
}

impl<T> PointCells<T> {
    /// Empty, with cubes of `cell_m` (a size that is not positive and finite puts every item among
    /// the strays, so that every search scans them all: slower, never wrong).
    pub(crate) fn new(cell_m: f64) -> Self {
        Self {
            cell_m,
            members: HashMap::new(),
            strays: Vec::new(),
            low: IVec3::MAX,
            high: IVec3::MIN,
        }
    }

    /// The side of a cell, metres.
    pub(crate) fn cell_m(&self) -> f64 {
        self.cell_m
    }

    /// `p`'s cell; `None` beyond 10^6 cells (or NaN), where a search scans every cell.
    pub(crate) fn cell(&self, p: DVec3) -> Option<IVec3> {
        let c = (p / self.cell_m).floor();
        (c.abs().max_element() <= 1e6).then(|| c.as_ivec3())
    }

    pub(crate) fn insert(&mut self, p: DVec3, item: T) {
        let Some(c) = self.cell(p) else {
            self.strays.push(item);
            return;
        };
        self.members.entry(c).or_default().push(item);
        self.low = self.low.min(c);
        self.high = self.high.max(c);
    }

    /// The items without a cell.
    pub(crate) fn strays(&self) -> &[T] {
        &self.strays
    }

    /// The items of cell `c`.
    pub(crate) fn members(&self, c: IVec3) -> &[T] {
        self.members.get(&c).map_or(&[], Vec::as_slice)
    }

    /// The ring whose cube around `centre` contains every occupied cell.
    pub(crate) fn rings_to_cover(&self, centre: IVec3) -> i32 {
        let far = (centre - self.low).abs().max((self.high - centre).abs());
        far.max_element().max(0)
    }

    /// The occupied-bounds cells at Chebyshev distance exactly `ring` from `centre`.
    pub(crate) fn ring(&self, centre: IVec3, ring: i32) -> impl Iterator<Item = IVec3> + '_ {
        let lo = (centre - IVec3::splat(ring)).max(self.low);
        let hi = (centre + IVec3::splat(ring)).min(self.high);
        (lo.x..=hi.x).flat_map(move |x| {
            (lo.y..=hi.y).flat_map(move |y| {
                let on_side = (x - centre.x).abs() == ring || (y - centre.y).abs() == ring;
                let clip = |z: i32| z.max(lo.z)..=z.min(hi.z);
                // On the ring's sides every z; inside them only its top and bottom faces.
                let (first, second) = if on_side {
                    (lo.z..=hi.z, hi.z + 1..=hi.z)
                } else {
                    (clip(centre.z - ring), clip(centre.z + ring))
                };
                first.chain(second).map(move |z| IVec3::new(x, y, z))
            })
        })
    }

    /// Every item whose point may lie within `radius_m` of `p`, and others: the strays and the
    /// items of every cell within `radius_m` (plus a margin far above the rounding of `p /
    /// cell_m`) of `p`'s cell; every item when `p` has no cell. The caller tests the distance.
    pub(crate) fn near(&self, p: DVec3, radius_m: f64) -> impl Iterator<Item = &T> + '_ {
        let centre = self.cell(p);
        let around = centre.into_iter().flat_map(move |centre| {
            let reach = radius_m / self.cell_m + 1e-6;
            let rings = if reach.is_finite() {
                (reach.floor() as i32)
                    .saturating_add(1)
                    .min(self.rings_to_cover(centre))
            } else {
                self.rings_to_cover(centre)
            };
            (0..=rings).flat_map(move |ring| self.ring(centre, ring))
        });
        let everywhere = centre.is_none().then(|| self.members.values().flatten());
        self.strays
            .iter()
            .chain(around.flat_map(|c| self.members(c).iter()))
            .chain(everywhere.into_iter().flatten())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    /// The items a scan of every point finds within `radius_m` of `p`, sorted.
    fn scan(points: &[DVec3], p: DVec3, radius_m: f64) -> Vec<usize> {
        (0..points.len())
            .filter(|&i| points[i].distance_squared(p) <= radius_m * radius_m)
            .collect()
    }

    #[test]
    fn the_cells_near_a_point_hold_what_a_scan_finds() {
        let mut rng = crate::rng::rng(3);
        let mut points: Vec<DVec3> = (0..2000)
            .map(|_| {
                DVec3::new(
                    rng.random_range(-0.3..0.3),
                    rng.random_range(-0.3..0.3),
                    rng.random_range(0.0..0.4),
                )
            })
            .collect();
        // Points on cell boundaries, and one without a cell.
        points.extend([
            DVec3::splat(0.05),
            DVec3::new(0.1, -0.05, 0.15),
            DVec3::splat(f64::NAN),
        ]);
        for cell_m in [0.01, 0.05, 0.2] {
            let mut cells = PointCells::new(cell_m);
            for (i, &p) in points.iter().enumerate() {
                cells.insert(p, i);
            }
            for radius_m in [0.0, 0.025, 0.05, 0.13] {
                for q in points
                    .iter()
                    .take(300)
                    .chain(&[DVec3::new(0.1, 0.0, 0.15), DVec3::splat(9.0)])
                {
                    let mut found: Vec<usize> = cells
                        .near(*q, radius_m)
                        .copied()
                        .filter(|&i| points[i].distance_squared(*q) <= radius_m * radius_m)
                        .collect();
                    found.sort_unstable();
                    assert_eq!(
                        found,
                        scan(&points, *q, radius_m),
                        "cell {cell_m}, radius {radius_m}, at {q}"
                    );
                }
            }
        }
    }

    #[test]
    fn without_a_usable_cell_size_every_item_is_offered() {
        let mut cells = PointCells::new(0.0);
        cells.insert(DVec3::ZERO, 1);
        cells.insert(DVec3::X, 2);
        assert_eq!(cells.strays(), &[1, 2]);
        assert_eq!(cells.near(DVec3::Y, 0.01).count(), 2);
    }
}
