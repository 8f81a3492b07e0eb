//! Finite-volume grid and the film-thickness shape (docs/model.md §1).
//!
//! ```text
//! h(x,t) = h0(t) + hg(x) + ht(x)
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | x | position along the slider, 0..L | m |
//! | h0 | minimum nominal separation (the rigid-body unknown) | m |
//! | hg | global profile (parabolic, linear taper, flat) | m |
//! | ht | texture (rectangular pockets) | m |
//! | Δx = L/N | cell width | m |
//!
//! Cells are `[iΔx, (i+1)Δx]`. The shape `g = hg + ht` is stored at the N+1
//! faces (point values, used in the face fluxes) and as exact cell averages
//! (used in the storage term, GW contact and shear), so both are second
//! order for smooth profiles and conservative for pockets.

use super::params::{Geometry, Profile};

/// Grid and shape arrays; allocated once.
#[derive(Debug, Clone)]
pub struct Grid {
    /// Cells along x.
    pub n: usize,
    /// Slider length L, m.
    pub length: f64,
    /// Slider width B, m.
    pub width: f64,
    /// Cell width Δx = L / n, m.
    pub dx: f64,
    /// g at faces, N+1 values.
    pub g_face: Vec<f64>,
    /// Cell-average g, N values.
    pub g_cell: Vec<f64>,
    /// min over x of g (the film minimum is h0 + g_min).
    pub g_min: f64,
}

impl Grid {
    /// The grid of `n` cells over `geom` (profile and pockets sampled on it).
    pub fn new(geom: &Geometry, n: usize) -> Self {
        let l = geom.length;
        let dx = l / n as f64;
        let g_face: Vec<f64> = (0..=n).map(|f| shape_at(geom, f as f64 * dx)).collect();
        let g_cell: Vec<f64> = (0..n)
            .map(|i| shape_average(geom, i as f64 * dx, (i + 1) as f64 * dx))
            .collect();
        // The profiles are minimal at x = L/2 (parabolic), x = L (linear) or
        // everywhere (flat); pockets only deepen the gap.
        let g_min = [0.0, 0.5 * l, l]
            .iter()
            .map(|&x| shape_at(geom, x))
            .chain(g_face.iter().copied())
            .fold(f64::INFINITY, f64::min)
            .max(0.0);
        Self {
            n,
            length: l,
            width: geom.width,
            dx,
            g_face,
            g_cell,
            g_min,
        }
    }

    /// Cell-centre coordinate.
    pub fn x_cell(&self, i: usize) -> f64 {
        (i as f64 + 0.5) * self.dx
    }
}

/// hg(x) + ht(x) at a point.
pub fn shape_at(geom: &Geometry, x: f64) -> f64 {
    let l = geom.length;
    let hg = match geom.profile {
        Profile::Parabolic { depth } => {
            let xi = x / l - 0.5;
            4.0 * depth * xi * xi
        }
        Profile::Linear { depth } => depth * (1.0 - x / l),
        Profile::Flat => 0.0,
    };
    let ht: f64 = geom
        .pockets
        .iter()
        .filter(|p| x >= p.start && x < p.start + p.width)
        .map(|p| p.depth)
        .sum();
    hg + ht
}

/// Exact average of hg + ht over [a, b].
pub fn shape_average(geom: &Geometry, a: f64, b: f64) -> f64 {
    let l = geom.length;
    let w = b - a;
    let hg = match geom.profile {
        Profile::Parabolic { depth } => {
            let (xa, xb) = (a / l - 0.5, b / l - 0.5);
            4.0 * depth * l * (xb.powi(3) - xa.powi(3)) / (3.0 * w)
        }
        Profile::Linear { depth } => depth * (1.0 - 0.5 * (a + b) / l),
        Profile::Flat => 0.0,
    };
    let ht: f64 = geom
        .pockets
        .iter()
        .map(|p| {
            let overlap = (b.min(p.start + p.width) - a.max(p.start)).max(0.0);
            p.depth * overlap / w
        })
        .sum();
    hg + ht
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // the values compared exactly are exact claims (0, 1, representable sums)
mod tests {
    use super::*;
    use crate::physics::params::Pocket;
    use approx::assert_relative_eq;

    #[test]
    fn parabolic_profile_has_its_depth_at_the_edges_and_zero_at_the_centre() {
        let g = Geometry::default();
        assert_relative_eq!(shape_at(&g, 0.0), 25.4e-6, max_relative = 1e-12);
        assert_relative_eq!(shape_at(&g, g.length), 25.4e-6, max_relative = 1e-12);
        assert_eq!(shape_at(&g, 0.5 * g.length), 0.0);
    }

    #[test]
    fn cell_averages_integrate_the_profile_exactly() {
        let mut g = Geometry::default();
        g.pockets.push(Pocket {
            start: 0.01,
            width: 0.005,
            depth: 5e-6,
        });
        let grid = Grid::new(&g, 37);
        let total: f64 = grid.g_cell.iter().sum::<f64>() * grid.dx;
        // ∫ 4d (x/L−½)² dx = d L / 3 ; pocket adds depth × width.
        let exact = 25.4e-6 * g.length / 3.0 + 5e-6 * 0.005;
        assert_relative_eq!(total, exact, max_relative = 1e-12);
    }
}
