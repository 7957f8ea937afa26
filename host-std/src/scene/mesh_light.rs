//! A mesh light as the core's lights: one triangle light per face with an area (a face without
//! one emits nothing and no ray meets it), for the scene format's `mesh` lights and USD's mesh
//! and cylinder lights alike. The faces of a mesh with an IES profile share one grid of the
//! profile's emission ([`TiltedGrid`]), from which each face's power is a sum rather than a
//! fresh integral over the profile.

use sampler_core::glam::Vec3;
use sampler_core::light::{LightError, SceneLight, Shaping, TILTED_GRID_CELLS, TiltedGrid, TriangleLight};

/// Appends the triangle lights of the mesh (`positions`, `triangles`) emitting `radiance`, on both
/// sides when `two_sided`, shaped by `shaping` (about the light's axis, not each face's normal),
/// to `out`; returns how many. On an error `out` is left as it was.
pub(crate) fn push_triangle_lights(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    radiance: Vec3,
    two_sided: bool,
    shaping: Shaping,
    out: &mut Vec<SceneLight>,
) -> Result<usize, LightError> {
    let before = out.len();
    let mut cells = Vec::new();
    if shaping.profile().is_some() {
        cells.resize(TILTED_GRID_CELLS, (Vec3::ZERO, Vec3::ZERO));
    }
    let grid = TiltedGrid::build(&shaping, &mut cells);
    for t in triangles {
        match TriangleLight::new(t.map(|i| positions[i as usize]), radiance) {
            Ok(l) => out.push(l.with_two_sided(two_sided).with_shaping_on_grid(shaping, &grid).into()),
            Err(LightError::ZeroArea) => {}
            Err(e) => {
                out.truncate(before);
                return Err(e);
            }
        }
    }
    Ok(out.len() - before)
}
