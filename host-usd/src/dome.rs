//! DomeLight and DomeLight_1. The lat-long texture's top pole is the light's local +Y, the
//! image centre +Z, u = ¼ → +X (u = ½ − atan2(x, z)/2π, v = ½ − asin(y)/π), then the
//! light's world rotation. DomeLight_1 with `poleAxis = Z`, or `poleAxis = scene` (also when
//! unset) on a Z-up stage, first adds rotateX(+90°), taking the pole to +Z; the legacy
//! DomeLight ignores upAxis. Radiance = texture · color · intensity · 2^exposure (·
//! the blackbody colour of `colorTemperature` when enabled; `normalize` does not apply).

use crate::scene::Dome;
use crate::stage::{PrimPath, Stage, Value};
use glam::{DMat3, DMat4, Vec3};

/// A light input: `inputs:<name>`, or the pre-UsdLux-2021 `<name>`.
fn light_input(stage: &Stage, prim: &PrimPath, name: &str) -> Result<Option<Value>, String> {
    match stage.value(prim, &format!("inputs:{name}"))? {
        Some(v) => Ok(Some(v)),
        None => stage.value(prim, name),
    }
}

/// Reads a dome light. `world` is its local-to-world in the stage frame, `conversion` the
/// up-axis rotation into the renderer's frame. Returns the dome and what was not honoured.
pub fn read(
    stage: &Stage,
    prim: &PrimPath,
    type_name: &str,
    z_up: bool,
    world: &DMat4,
    conversion: &DMat4,
) -> Result<(Dome, Vec<String>), String> {
    let mut notes = Vec::new();
    let scalar = |name: &str, d: f64| -> Result<f64, String> {
        Ok(light_input(stage, prim, name)?.and_then(|v| v.scalar()).unwrap_or(d))
    };
    let intensity = scalar("intensity", 1.0)?;
    let exposure = scalar("exposure", 0.0)?;
    let color = match light_input(stage, prim, "color")? {
        Some(Value::Numbers { values, .. }) if values.len() >= 3 => {
            Vec3::new(values[0] as f32, values[1] as f32, values[2] as f32)
        }
        _ => Vec3::ONE,
    };
    let mut radiance = color * (intensity * exposure.exp2()) as f32;
    if scalar("enableColorTemperature", 0.0)? != 0.0 {
        radiance *= crate::blackbody::rgb(scalar("colorTemperature", crate::blackbody::WHITE_KELVIN)?).as_vec3();
    }

    let format = light_input(stage, prim, "texture:format")?.and_then(|v| v.token().map(str::to_string));
    let format = format.unwrap_or_else(|| "automatic".into());
    let texture = match light_input(stage, prim, "texture:file")? {
        Some(Value::Asset { authored, resolved }) if !authored.is_empty() => {
            if format != "latlong" && format != "automatic" {
                notes.push(format!("texture:format {format} not supported; the dome renders its colour only"));
                None
            } else {
                let resolved = resolved.ok_or_else(|| format!("dome texture {authored} not found"))?;
                let bytes = stage.read_asset(&resolved).map_err(|e| format!("dome texture {resolved}: {e}"))?;
                Some((resolved, bytes))
            }
        }
        _ => None,
    };
    if !stage.targets(prim, "portals")?.is_empty() {
        notes.push("portals ignored".into());
    }

    let pole = stage.value(prim, "poleAxis")?.and_then(|v| v.token().map(str::to_string));
    let pole_to_z = type_name == "DomeLight_1"
        && match pole.as_deref().unwrap_or("scene") {
            "Z" => true,
            "scene" => z_up,
            _ => false,
        };
    let pole_fix = if pole_to_z { DMat3::from_rotation_x(std::f64::consts::FRAC_PI_2) } else { DMat3::IDENTITY };
    let map_to_world = DMat3::from_mat4(*conversion) * crate::xform::rotation_part(world) * pole_fix;
    Ok((Dome { path: prim.to_string(), texture, radiance, map_to_world }, notes))
}
