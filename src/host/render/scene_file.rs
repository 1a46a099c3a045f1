//! The scene file: the TOML schema as serde reads it, the value checks (each error
//! names the value's line) and the parse into a [`Scene`].

use crate::host::error::{Error, Result};
use crate::host::render::geometry::{AreaLight, Camera, Material, Quad, Sphere};
use crate::host::render::scene::Scene;
use crate::host::render::scene_scale;
use glam::Vec3;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

impl Scene {
    /// Read a scene file; errors name the file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Scene> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::new(format!("cannot read scene file {}: {e}", path.display())))?;
        Scene::from_toml_str(&text, &path.display().to_string())
    }

    /// Parse a scene; `origin_name` (usually the file name) prefixes every error,
    /// followed by the line of the offending value.
    pub fn from_toml_str(text: &str, origin_name: &str) -> Result<Scene> {
        let at = |span: Option<Range<usize>>, msg: String| {
            Error::new(match span {
                Some(s) => format!("{origin_name}:{}: {msg}", line_of(text, s.start)),
                None => format!("{origin_name}: {msg}"),
            })
        };
        let file: SceneFile =
            toml::from_str(text).map_err(|e| at(e.span(), e.message().trim_end().to_string()))?;
        let check = Checker { at: &at };
        let epsilon = file.ray_epsilon().map_err(|(span, msg)| at(span, msg))?;

        let cam = &file.camera;
        let position = check.point("camera position", &cam.position)?;
        let look_at = check.point("camera look_at", &cam.look_at)?;
        let up_hint = check.point("camera up", &cam.up)?;
        let fov = check.finite("camera fov_deg", &cam.fov_deg)?;
        if !(fov > 0.0 && fov < 180.0) {
            return Err(at(
                Some(cam.fov_deg.span()),
                format!(
                    "camera fov_deg must be in (0, 180), got {}",
                    cam.fov_deg.get_ref()
                ),
            ));
        }
        let forward = (look_at - position).normalize_or_zero();
        if forward == Vec3::ZERO {
            return Err(at(
                Some(cam.look_at.span()),
                format!(
                    "camera look_at {:?} equals the camera position",
                    cam.look_at.get_ref()
                ),
            ));
        }
        let right = forward.cross(up_hint).normalize_or_zero();
        if right == Vec3::ZERO || forward.cross(up_hint).length() < 1e-6 * up_hint.length() {
            return Err(at(
                Some(cam.up.span()),
                format!(
                    "camera up {:?} is zero or parallel to the view direction",
                    cam.up.get_ref()
                ),
            ));
        }
        let camera = Camera {
            position,
            forward,
            right,
            up: right.cross(forward),
            tan_half_fov: (fov.to_radians() * 0.5).tan(),
            eps: epsilon,
        };

        let mut materials = Vec::new();
        let mut material_names = Vec::new();
        for (name, spanned) in &file.materials {
            let span = Some(spanned.span());
            let material = match *spanned.get_ref() {
                MaterialFile::Diffuse { rgb } => {
                    if rgb.iter().any(|c| !(0.0..=1.0).contains(c)) {
                        return Err(at(
                            span,
                            format!(
                                "material '{name}': rgb {rgb:?} has a component outside [0, 1] \
                                 (an albedo above 1 creates energy)"
                            ),
                        ));
                    }
                    Material::Diffuse { albedo: vec3(rgb) }
                }
                MaterialFile::Mirror {} => Material::Mirror,
                MaterialFile::Glass { ior } => {
                    if !ior.is_finite() || ior <= 0.0 {
                        return Err(at(
                            span,
                            format!(
                                "material '{name}': ior must be a finite number > 0, got {ior}"
                            ),
                        ));
                    }
                    Material::Glass { ior: ior as f32 }
                }
            };
            materials.push(material);
            material_names.push(name.clone());
        }
        let material_index = |m: &Spanned<String>| {
            material_names
                .iter()
                .position(|n| n == m.get_ref())
                .ok_or_else(|| {
                    at(
                        Some(m.span()),
                        format!(
                            "unknown material '{}' (defined: {})",
                            m.get_ref(),
                            if material_names.is_empty() {
                                "none".to_string()
                            } else {
                                material_names.join(", ")
                            }
                        ),
                    )
                })
        };

        let mut quads = Vec::new();
        for q in &file.quad {
            let quad = check.quad("quad", &q.corner, &q.edge_u, &q.edge_v)?;
            quads.push((quad, material_index(&q.material)?));
        }
        let mut spheres = Vec::new();
        for s in &file.sphere {
            let center = check.point("sphere center", &s.center)?;
            let radius = check.finite("sphere radius", &s.radius)?;
            if radius <= 0.0 {
                return Err(at(
                    Some(s.radius.span()),
                    format!("sphere radius must be > 0, got {}", s.radius.get_ref()),
                ));
            }
            spheres.push((Sphere { center, radius }, material_index(&s.material)?));
        }

        let l = &file.light;
        let quad = check.quad("light", &l.corner, &l.edge_u, &l.edge_v)?;
        let power = check.point("light power", &l.power)?;
        if power.min_element() < 0.0 || power.max_element() <= 0.0 {
            return Err(at(
                Some(l.power.span()),
                format!(
                    "light power {:?} must be >= 0 in every channel and > 0 in one",
                    l.power.get_ref()
                ),
            ));
        }

        Ok(Scene {
            camera,
            materials,
            material_names,
            quads,
            spheres,
            light: AreaLight { quad, power },
            epsilon,
        })
    }
}

/// 1-based line number of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

fn vec3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32)
}

/// Shared value checks, each reporting the value's own line.
struct Checker<'a, F: Fn(Option<Range<usize>>, String) -> Error> {
    at: &'a F,
}

impl<F: Fn(Option<Range<usize>>, String) -> Error> Checker<'_, F> {
    fn point(&self, what: &str, v: &Spanned<[f64; 3]>) -> Result<Vec3> {
        let p = vec3(*v.get_ref());
        // Checked after the f32 conversion so 1e300 (→ inf) is caught too.
        if !p.is_finite() {
            return Err((self.at)(
                Some(v.span()),
                format!("{what} {:?} is not a finite vector", v.get_ref()),
            ));
        }
        Ok(p)
    }

    fn finite(&self, what: &str, v: &Spanned<f64>) -> Result<f32> {
        let x = *v.get_ref() as f32;
        if !x.is_finite() {
            return Err((self.at)(
                Some(v.span()),
                format!("{what} {} is not a finite number", v.get_ref()),
            ));
        }
        Ok(x)
    }

    fn quad(
        &self,
        what: &str,
        corner: &Spanned<[f64; 3]>,
        edge_u: &Spanned<[f64; 3]>,
        edge_v: &Spanned<[f64; 3]>,
    ) -> Result<Quad> {
        let c = self.point(&format!("{what} corner"), corner)?;
        let u = self.point(&format!("{what} edge_u"), edge_u)?;
        let v = self.point(&format!("{what} edge_v"), edge_v)?;
        Quad::new(c, u, v).ok_or_else(|| {
            (self.at)(
                Some(edge_u.span()),
                format!(
                    "{what} has zero area: edge_u {:?} and edge_v {:?} are zero or parallel",
                    edge_u.get_ref(),
                    edge_v.get_ref()
                ),
            )
        })
    }
}

impl SceneFile {
    /// Every position of the file and the geometry's bounding points, for
    /// [`scene_scale::ray_epsilon`].
    fn ray_epsilon(&self) -> std::result::Result<f32, (Option<Range<usize>>, String)> {
        let loc = |what: &'static str, v: &Spanned<[f64; 3]>| scene_scale::Located {
            what,
            span: v.span(),
            value: *v.get_ref(),
        };
        let c = &self.camera;
        let mut points = vec![
            loc("camera position", &c.position),
            loc("camera look_at", &c.look_at),
        ];
        let mut geometry = Vec::new();
        let mut quad =
            |corner: &Spanned<[f64; 3]>, u: &Spanned<[f64; 3]>, v: &Spanned<[f64; 3]>| {
                let (c, u, v) = (*corner.get_ref(), *u.get_ref(), *v.get_ref());
                for (su, sv) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                    geometry.push([0, 1, 2].map(|a| c[a] + su * u[a] + sv * v[a]));
                }
            };
        for q in &self.quad {
            points.push(loc("quad corner", &q.corner));
            quad(&q.corner, &q.edge_u, &q.edge_v);
        }
        let l = &self.light;
        points.push(loc("light corner", &l.corner));
        quad(&l.corner, &l.edge_u, &l.edge_v);
        for s in &self.sphere {
            points.push(loc("sphere center", &s.center));
            let (c, r) = (*s.center.get_ref(), s.radius.get_ref().abs());
            geometry.push(c.map(|x| x - r));
            geometry.push(c.map(|x| x + r));
        }
        scene_scale::ray_epsilon(&points, &geometry)
    }
}

// The file format, as serde reads it. Values that can be wrong on their own carry
// their span so the error can point at their line.

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    camera: CameraFile,
    #[serde(default)]
    materials: BTreeMap<String, Spanned<MaterialFile>>,
    #[serde(default)]
    quad: Vec<QuadFile>,
    #[serde(default)]
    sphere: Vec<SphereFile>,
    light: LightFile,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraFile {
    position: Spanned<[f64; 3]>,
    look_at: Spanned<[f64; 3]>,
    up: Spanned<[f64; 3]>,
    fov_deg: Spanned<f64>,
}

/// Internally tagged by `type`. serde buffers tagged content before dispatching, so
/// the fields cannot carry spans; errors point at the material's table instead.
#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum MaterialFile {
    Diffuse { rgb: [f64; 3] },
    Mirror {},
    Glass { ior: f64 },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct QuadFile {
    corner: Spanned<[f64; 3]>,
    edge_u: Spanned<[f64; 3]>,
    edge_v: Spanned<[f64; 3]>,
    material: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereFile {
    center: Spanned<[f64; 3]>,
    radius: Spanned<f64>,
    material: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightFile {
    corner: Spanned<[f64; 3]>,
    edge_u: Spanned<[f64; 3]>,
    edge_v: Spanned<[f64; 3]>,
    power: Spanned<[f64; 3]>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::host::render::geometry::{Ray, Surface, RAY_EPSILON};

    const MINIMAL: &str = r#"
[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov_deg = 40.0

[materials.white]
type = "diffuse"
rgb = [0.5, 0.5, 0.5]

[materials.glass]
type = "glass"
ior = 1.5

[[quad]]
corner = [-1.0, -1.0, 0.0]
edge_u = [2.0, 0.0, 0.0]
edge_v = [0.0, 2.0, 0.0]
material = "white"

[[sphere]]
center = [0.0, 0.0, 1.0]
radius = 0.5
material = "glass"

[light]
corner = [-0.1, 0.9, -0.1]
edge_u = [0.2, 0.0, 0.0]
edge_v = [0.0, 0.0, 0.2]
power = [1.0, 1.0, 1.0]
"#;

    /// Replace the first occurrence of `from` in the minimal scene and parse it.
    fn parse_with(from: &str, to: &str) -> Result<Scene> {
        assert!(
            MINIMAL.contains(from),
            "test edit {from:?} not in the scene"
        );
        Scene::from_toml_str(&MINIMAL.replacen(from, to, 1), "test.toml")
    }

    /// 1-based line of the first occurrence of `needle` in `text`, found here
    /// independently of the parser's spans.
    fn line_containing(text: &str, needle: &str) -> usize {
        text.lines().position(|l| l.contains(needle)).unwrap() + 1
    }

    fn assert_error(from: &str, to: &str, line_needle: &str, value: &str) {
        let edited = MINIMAL.replacen(from, to, 1);
        let err = parse_with(from, to).unwrap_err().to_string();
        let line = line_containing(&edited, line_needle);
        assert!(
            err.starts_with(&format!("test.toml:{line}:")),
            "error {err:?} should point at line {line}"
        );
        assert!(err.contains(value), "error {err:?} should name {value:?}");
    }

    #[test]
    fn minimal_scene_parses() {
        let s = Scene::from_toml_str(MINIMAL, "test.toml").unwrap();
        assert_eq!(s.quads.len(), 1);
        assert_eq!(s.spheres.len(), 1);
        assert_eq!(s.material_names[s.quads[0].1], "white");
        assert_eq!(s.materials[s.spheres[0].1], Material::Glass { ior: 1.5 });
        // edge_u × edge_v = x × z = −y: the light faces down.
        assert_eq!(s.light.quad.normal, Vec3::new(0.0, -1.0, 0.0));
        assert!((s.light.quad.area - 0.04).abs() < 1e-6);
        assert_eq!(s.camera.forward, Vec3::new(0.0, 0.0, -1.0));
    }

    #[test]
    fn cornell_box_parses() {
        let s = Scene::cornell_box();
        assert_eq!(s.quads.len(), 5);
        assert_eq!(s.spheres.len(), 2);
        assert!(s.light.quad.normal.y < -0.99, "light must face down");
    }

    #[test]
    fn unknown_material_names_line_and_value() {
        assert_error(
            "material = \"glass\"",
            "material = \"glas\"",
            "\"glas\"",
            "glas",
        );
    }

    #[test]
    fn albedo_out_of_range_names_line_and_value() {
        // The span of a [materials.x] table starts at its header.
        let err = parse_with("rgb = [0.5, 0.5, 0.5]", "rgb = [0.5, 1.5, 0.5]")
            .unwrap_err()
            .to_string();
        assert!(err.contains("1.5") && err.contains("white"), "{err}");
        let line = line_containing(MINIMAL, "[materials.white]");
        let rgb_line = line_containing(MINIMAL, "rgb =");
        let reported: usize = err.split(':').nth(1).unwrap().parse().unwrap();
        assert!((line..=rgb_line).contains(&reported), "{err}");
    }

    #[test]
    fn bad_ior_names_value() {
        let err = parse_with("ior = 1.5", "ior = -2.0")
            .unwrap_err()
            .to_string();
        assert!(err.contains("-2") && err.contains("ior"), "{err}");
        assert!(err.starts_with("test.toml:"), "{err}");
    }

    #[test]
    fn bad_radius_names_line_and_value() {
        assert_error("radius = 0.5", "radius = -0.25", "radius", "-0.25");
        assert_error("radius = 0.5", "radius = 0.0", "radius", "0");
    }

    #[test]
    fn zero_area_quad_names_line_and_value() {
        assert_error(
            "edge_u = [2.0, 0.0, 0.0]",
            "edge_u = [0.0, 3.0, 0.0]",
            "edge_u = [0.0, 3.0",
            "[0.0, 3.0, 0.0]",
        );
    }

    #[test]
    fn nan_names_line_and_value() {
        assert_error(
            "center = [0.0, 0.0, 1.0]",
            "center = [0.0, nan, 1.0]",
            "nan",
            "NaN",
        );
    }

    #[test]
    fn missing_field_names_line_and_field() {
        let edited = MINIMAL.replacen("radius = 0.5\n", "", 1);
        let err = Scene::from_toml_str(&edited, "test.toml")
            .unwrap_err()
            .to_string();
        assert!(err.contains("radius"), "{err}");
        // toml reports the table lacking the field: the [[sphere]] header.
        let line = line_containing(&edited, "[[sphere]]");
        assert!(err.starts_with(&format!("test.toml:{line}:")), "{err}");
    }

    #[test]
    fn unreadable_file_names_path() {
        let err = Scene::from_file("/nonexistent/dir/scene.toml")
            .unwrap_err()
            .to_string();
        assert!(err.contains("/nonexistent/dir/scene.toml"), "{err}");
    }

    #[test]
    fn from_file_reads_and_names_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.toml");
        std::fs::write(&path, MINIMAL.replacen("radius = 0.5", "radius = -1.0", 1)).unwrap();
        let err = Scene::from_file(&path).unwrap_err().to_string();
        assert!(err.starts_with(&path.display().to_string()), "{err}");
        std::fs::write(&path, MINIMAL).unwrap();
        assert!(Scene::from_file(&path).is_ok());
    }

    #[test]
    fn scene_intersect_picks_nearest_and_reports_light() {
        let s = Scene::from_toml_str(MINIMAL, "test.toml").unwrap();
        // Straight down the z axis: the sphere (front at z = 1.5) before the quad.
        let hit = s
            .intersect(&Ray {
                origin: Vec3::new(0.0, 0.0, 5.0),
                dir: -Vec3::Z,
                eps: RAY_EPSILON,
            })
            .unwrap();
        assert!((hit.t - 3.5).abs() < 1e-5);
        assert_eq!(hit.surface, Surface::Material(s.spheres[0].1));
        // Straight up from below the light hits it.
        let hit = s
            .intersect(&Ray {
                origin: Vec3::new(0.0, 0.7, 0.0),
                dir: Vec3::Y,
                eps: RAY_EPSILON,
            })
            .unwrap();
        assert_eq!(hit.surface, Surface::Light);
        assert!((hit.t - 0.2).abs() < 1e-5);
    }
}
