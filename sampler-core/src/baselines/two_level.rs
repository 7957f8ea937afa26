//! The two-level product (after Conty Estevez & Lecocq, "Fast product importance sampling of
//! environment maps", SIGGRAPH 2018 talk): a cheaper product than the quadtree's, with no BRDF
//! samples at all.
//!
//! * The coarse level is one level `L` of the environment's own pyramid: `4^L` cells of the
//!   equal-area square (8×8 to 32×32), each with its integrated importance already in the
//!   pyramid, each with a bounding cone of its directions ([`crate::cone`]), computed once.
//! * Per shading point every cell's B̃ is an upper bound of B·cos over its cone
//!   ([`Brdf::cone_bounds`]), so the product never starves a cell the BRDF reaches, capped at
//!   the BRDF's whole reflectance over the cell's solid angle ([`Brdf::reflectance_bound`]), so
//!   that a needle lobe's peak does not stand for its mean over the cell; a cell is drawn
//!   ∝ B̃ × ∫L.
//! * The fine level is the rest of the pyramid below the drawn cell: a texel ∝ L inside it, and
//!   a point uniformly in the texel.
//!
//! * In its MIS form ([`TwoLevelArena::build_for_mis`]) the cells are MIS-compensated, as the
//!   map is for MIS's env samples ([`crate::env::compensate_pyramid`]): BRDF samples already
//!   cover the light the lobe sees on average, so a cell is weighted by B̃ × the larger of its
//!   mean less that average (the cells' means weighted by B̃) and its mean of what stands
//!   above the map's mean (the compensated pyramid), which keeps a small bright source in a
//!   dim cell. Where neither is above zero the cell is left to the BRDF samples. Measured in
//!   docs/perf.md, "The two products".
//!
//! The density of a direction is P(cell) × 4^L × L_texel / L̄_cell per unit area of the square.
//! A BRDF without a bound gets B̃ by evaluation at each cone's axis and four points of its rim,
//! every cell floored at [`ESTIMATE_FLOOR`] of the largest, so that no cell where B > 0 is left
//! out.

use crate::brdf::Brdf;
use crate::cell::Cell;
use crate::cone::{Cone, cell_count, level_of, morton_cell};
use crate::env::{EnvHierarchy, IN_FLIGHT, WarpLane, level_offset, luminance};
use crate::frame::Frame;
use crate::mapping::SPHERE_AREA;
use crate::sampler::DirectionSample;
use crate::warp::ONE_MINUS_EPSILON;
use glam::{DVec2, Vec2, Vec3};

/// Where B̃ is estimated by evaluation, each cell's weight is at least this fraction of the
/// largest.
pub const ESTIMATE_FLOOR: f64 = 1e-3;

/// Cones rotated into the shading frame per batch of the BRDF's bounds (a stack buffer).
const CHUNK: usize = 64;

/// Why a two-level sampler could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TwoLevelError {
    /// The cones are not one level of the square (their count is not a power of four).
    NotALevel {
        /// The number of cones given.
        cones: usize,
    },
    /// The level is finer than the map.
    FinerThanMap {
        /// The level of the cones.
        level: u32,
        /// The map's finest level.
        finest: u32,
    },
    /// The level has more cells than the arena holds.
    AboveCapacity {
        /// Cells of the level.
        cells: usize,
        /// The arena's capacity.
        capacity: usize,
    },
}

impl core::fmt::Display for TwoLevelError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::NotALevel { cones } => write!(f, "{cones} cones are not one level of the square (4^L)"),
            Self::FinerThanMap { level, finest } => {
                write!(f, "coarse level {level} is finer than the map's finest level {finest}")
            }
            Self::AboveCapacity { cells, capacity } => {
                write!(f, "{cells} coarse cells exceed the arena's capacity of {capacity}")
            }
        }
    }
}

impl core::error::Error for TwoLevelError {}

/// Scratch memory of the two-level product for one thread: the cells' cumulative weights.
/// `CELLS` is the largest coarse level it serves (1024: 32×32).
#[derive(Clone, Debug)]
pub struct TwoLevelArena<const CELLS: usize = 1024> {
    cumulative: [f64; CELLS],
    /// The last build's level and whether its B̃ was a bound (`None` before the first).
    built: Option<(u32, bool)>,
}

impl<const CELLS: usize> Default for TwoLevelArena<CELLS> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const CELLS: usize> TwoLevelArena<CELLS> {
    /// An empty arena.
    #[must_use]
    pub const fn new() -> Self {
        Self { cumulative: [0.0; CELLS], built: None }
    }

    /// The sampler the last [`build`](Self::build) made, again, without rebuilding it. `env`
    /// must be the environment it was built on. `None` before the first build.
    #[must_use]
    pub fn last_built<'a, 'e>(&'a self, env: &'a EnvHierarchy<'e>) -> Option<TwoLevelSampler<'a, 'e>> {
        let (level, bounded) = self.built?;
        Some(TwoLevelSampler { env, level, cumulative: &self.cumulative[..cell_count(level)], bounded })
    }

    /// The product of one shading point (world-space `wo`) over the coarse level whose cell cones
    /// are `cones` (from [`crate::cone::build_cell_cones`]; in the map's frame, Morton order).
    pub fn build<'a, 'e, B: Brdf + ?Sized>(
        &'a mut self,
        env: &'a EnvHierarchy<'e>,
        cones: &[Cone],
        brdf: &B,
        frame: &Frame,
        wo: Vec3,
    ) -> Result<TwoLevelSampler<'a, 'e>, TwoLevelError> {
        self.build_with(env, cones, brdf, frame, wo, false)
    }

    /// [`build`](Self::build) with its cells MIS-compensated (the module's documentation), for
    /// draws combined with BRDF samples only: a cell at or below the light its lobe sees on
    /// average and with nothing above the map's mean has no weight. Without a compensated
    /// pyramid attached to `env` ([`EnvHierarchy::with_compensated`]) no cell is.
    pub fn build_for_mis<'a, 'e, B: Brdf + ?Sized>(
        &'a mut self,
        env: &'a EnvHierarchy<'e>,
        cones: &[Cone],
        brdf: &B,
        frame: &Frame,
        wo: Vec3,
    ) -> Result<TwoLevelSampler<'a, 'e>, TwoLevelError> {
        self.build_with(env, cones, brdf, frame, wo, env.has_compensated())
    }

    /// [`build`](Self::build), its cells compensated where `compensate` says.
    fn build_with<'a, 'e, B: Brdf + ?Sized>(
        &'a mut self,
        env: &'a EnvHierarchy<'e>,
        cones: &[Cone],
        brdf: &B,
        frame: &Frame,
        wo: Vec3,
        compensate: bool,
    ) -> Result<TwoLevelSampler<'a, 'e>, TwoLevelError> {
        let cells = cones.len();
        let level = level_of(cells).ok_or(TwoLevelError::NotALevel { cones: cells })?;
        if level > env.finest_level() {
            return Err(TwoLevelError::FinerThanMap { level, finest: env.finest_level() });
        }
        if cells > CELLS {
            return Err(TwoLevelError::AboveCapacity { cells, capacity: CELLS });
        }
        self.built = None;
        let cumulative = &mut self.cumulative[..cells];
        let bounded = brdf.has_cone_bounds();
        let wo = frame.to_local(wo);
        // No cell's mean B·cos exceeds the whole reflectance over the cell's solid angle.
        let cap = brdf.reflectance_bound(wo).map_or(f32::INFINITY, |r| r * cell_count(level) as f32 / SPHERE_AREA);
        // Map frame → shading frame: the rows are the frame's axes seen in the map's frame.
        let rows = [env.to_map(frame.s), env.to_map(frame.t), env.to_map(frame.n)];
        let mut local = [Cone::default(); CHUNK];
        let mut bound = [0.0f32; CHUNK];
        for (start, chunk) in (0..cells).step_by(CHUNK).zip(cones.chunks(CHUNK)) {
            for (l, c) in local.iter_mut().zip(chunk) {
                *l = c.rotated(&rows);
            }
            let (local, bound) = (&local[..chunk.len()], &mut bound[..chunk.len()]);
            if bounded {
                brdf.cone_bounds(wo, local, bound);
            } else {
                for (b, c) in bound.iter_mut().zip(local) {
                    *b = estimate(brdf, wo, c);
                }
            }
            for (k, b) in bound.iter().enumerate() {
                cumulative[start + k] = f64::from(b.min(cap).max(0.0));
            }
        }
        let floor = if bounded { 0.0 } else { ESTIMATE_FLOOR * cumulative.iter().copied().fold(0.0, f64::max) };
        let level_cells = level_offset(level)..level_offset(level) + cells;
        let mass = &env.pyramid[level_cells.clone()];
        let weight = |w: f64| if w.is_finite() { w.max(floor) } else { f64::from(f32::MAX) };
        let mut total = 0.0f64;
        if compensate {
            let seen = lobe_mean(cumulative.iter().map(|&w| weight(w)), mass);
            let above = &env.compensated().pyramid[level_cells];
            for ((w, &m), &a) in cumulative.iter_mut().zip(mass).zip(above) {
                total += weight(*w) * (f64::from(m) - seen).max(f64::from(a));
                *w = total;
            }
        } else {
            for (w, &m) in cumulative.iter_mut().zip(mass) {
                total += weight(*w) * f64::from(m);
                *w = total;
            }
        }
        self.built = Some((level, bounded));
        let built: &'a Self = self;
        Ok(built.last_built(env).expect("just built"))
    }
}

/// The mean of the cells' `mass` weighted by their B̃ `weights`: the light the lobe sees on
/// average (0 where no cell has weight).
fn lobe_mean(weights: impl Iterator<Item = f64>, mass: &[f32]) -> f64 {
    let (mut seen, mut sum) = (0.0f64, 0.0f64);
    for (b, &m) in weights.zip(mass) {
        seen += b * f64::from(m);
        sum += b;
    }
    if sum > 0.0 && seen.is_finite() { seen / sum } else { 0.0 }
}

/// B̃ of a cone by evaluation: the largest luminance of B·cos at its axis and four rim points.
fn estimate<B: Brdf + ?Sized>(brdf: &B, wo: Vec3, cone: &Cone) -> f32 {
    let f = Frame::from_normal(cone.axis);
    let (c, s) = (cone.cos, cone.sin);
    let rim = [f.s, -f.s, f.t, -f.t].map(|v| (cone.axis * c + v * s).normalize());
    rim.iter().fold(luminance(brdf.eval(wo, cone.axis)), |m, &d| m.max(luminance(brdf.eval(wo, d))))
}

/// The two-level product distribution of one shading point, borrowing its arena.
#[derive(Clone, Copy, Debug)]
pub struct TwoLevelSampler<'a, 'e> {
    env: &'a EnvHierarchy<'e>,
    level: u32,
    /// Running sums of B̃ × mass over the cells, in Morton order.
    cumulative: &'a [f64],
    bounded: bool,
}

impl<'e> TwoLevelSampler<'_, 'e> {
    /// The environment it samples.
    #[must_use]
    pub fn env(&self) -> &EnvHierarchy<'e> {
        self.env
    }

    /// The coarse level (`2^level × 2^level` cells).
    #[must_use]
    pub fn level(&self) -> u32 {
        self.level
    }

    /// True when B̃ is the BRDF's bound; false when it was estimated by evaluation.
    #[must_use]
    pub fn is_bounded(&self) -> bool {
        self.bounded
    }

    /// Σ B̃ × mass over every cell: 0 when nothing can be drawn.
    #[must_use]
    pub fn total(&self) -> f64 {
        self.cumulative.last().copied().unwrap_or(0.0)
    }

    /// Draws a direction; `None` when no cell has weight.
    pub fn sample(&self, u: DVec2) -> Option<DirectionSample> {
        let (c, mut xi) = self.draw_cell(u)?;
        let (cx, cy) = morton_cell(c);
        let texel = self.env.warp_down(Cell::new(self.level, cx, cy), &mut xi)?;
        let uv = texel.point(xi);
        let pdf = self.pdf_texel(c, texel) / SPHERE_AREA;
        (pdf > 0.0).then(|| DirectionSample { dir: self.env.dir_of(uv), uv, pdf })
    }

    /// [`sample`](Self::sample) for every point of `u` (as many as both hold): the cells
    /// drawn first, then the descents below them side by side, as the environment's own
    /// [`EnvHierarchy::sample_many`] advances them. The same distribution and pdf; the point
    /// within a texel can differ from [`sample`](Self::sample)'s in the last bits.
    pub fn sample_many(&self, u: &[DVec2], out: &mut [Option<DirectionSample>]) {
        for (us, os) in u.chunks(IN_FLIGHT).zip(out.chunks_mut(IN_FLIGHT)) {
            let n = us.len().min(os.len());
            let mut lanes = [WarpLane::default(); IN_FLIGHT];
            let mut cells = [0usize; IN_FLIGHT];
            for ((lane, cell), &u) in lanes.iter_mut().zip(&mut cells).zip(&us[..n]) {
                if let Some((c, xi)) = self.draw_cell(u) {
                    let (cx, cy) = morton_cell(c);
                    (*lane, *cell) = (WarpLane::new(Cell::new(self.level, cx, cy), xi), c);
                }
            }
            self.env.warp_down_lanes(&mut lanes[..n]);
            let finest = self.env.finest_level();
            let mut points = [(Vec2::ZERO, 0.0f32); IN_FLIGHT];
            for ((p, lane), &c) in points.iter_mut().zip(&lanes[..n]).zip(&cells) {
                let texel = self.env.node_relative_at(finest, lane.morton);
                *p = (lane.cell.point(lane.xi), self.pdf_of(c, texel) / SPHERE_AREA);
            }
            let mut dirs = [Vec3::ZERO; IN_FLIGHT];
            self.env.dirs_of(&points.map(|(uv, _)| uv)[..n], &mut dirs[..n]);
            for (k, (o, lane)) in os.iter_mut().zip(&lanes[..n]).enumerate() {
                let (uv, pdf) = points[k];
                *o = (lane.alive && pdf > 0.0).then_some(DirectionSample { dir: dirs[k], uv, pdf });
            }
        }
    }

    /// The coarse cell `u` draws ∝ B̃ × mass, and the point rescaled within it; `None` when no
    /// cell has weight.
    #[inline]
    fn draw_cell(&self, u: DVec2) -> Option<(usize, DVec2)> {
        let total = self.total();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let mut xi = u.clamp(DVec2::ZERO, DVec2::splat(ONE_MINUS_EPSILON));
        let t = xi.x * total;
        let c = self.cumulative.partition_point(|&w| w <= t).min(self.cumulative.len() - 1);
        let (lo, hi) = self.bounds(c);
        if hi <= lo {
            return None;
        }
        xi.x = ((t - lo) / (hi - lo)).clamp(0.0, ONE_MINUS_EPSILON);
        Some((c, xi))
    }

    /// The running sums before and after cell `c`.
    #[inline]
    fn bounds(&self, c: usize) -> (f64, f64) {
        (if c == 0 { 0.0 } else { self.cumulative[c - 1] }, self.cumulative[c])
    }

    /// Density per unit area of the square in a finest-level texel of cell `c`.
    fn pdf_texel(&self, c: usize, texel: Cell) -> f32 {
        self.pdf_of(c, self.env.node_relative(texel))
    }

    /// Density per unit area of the square in a finest-level texel of cell `c` whose relative
    /// importance is `texel`.
    #[inline]
    fn pdf_of(&self, c: usize, texel: f32) -> f32 {
        let total = self.total();
        let (lo, hi) = self.bounds(c);
        let cell = f64::from(self.env.node_relative_at(self.level, c));
        if !(total > 0.0 && cell > 0.0) {
            return 0.0;
        }
        ((hi - lo) / total * cell_count(self.level) as f64 * f64::from(texel) / cell) as f32
    }

    /// Density per unit area of the square at `uv`.
    #[must_use]
    pub fn pdf_square(&self, uv: Vec2) -> f32 {
        let (x, y) = self.env.texel_at(uv);
        let texel = Cell::new(self.env.finest_level(), x, y);
        self.pdf_texel(texel.ancestor(self.level).morton(), texel)
    }

    /// Density with respect to solid angle of world direction `dir`.
    #[must_use]
    pub fn pdf(&self, dir: Vec3) -> f32 {
        self.pdf_square(self.env.square_of(dir)) / SPHERE_AREA
    }
}
