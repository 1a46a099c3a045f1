//! The scene: a pinhole camera, diffuse / mirror / glass materials, quads, spheres
//! and one parallelogram area light, read from a small TOML format.
//!
//! Scenes here are a handful of primitives (the Cornell box has eight), so ray
//! intersection is a plain loop over them: an acceleration structure would cost more
//! code than it saves. Geometry is f32 (glam `Vec3`); the ray epsilon is 1e-4 of the
//! scene's size (`scene_scale`), far above the f32 rounding of hit points (~1e-7 of
//! it) and far below any feature size, so a scene renders the same at any scale f32
//! can hold; one it cannot hold is refused with that reason.
//!
//! # File format
//! ```toml
//! [camera]
//! position = [0.5, 0.5, 2.3]
//! look_at = [0.5, 0.5, 0.0]
//! up = [0.0, 1.0, 0.0]
//! fov_deg = 40.0            # vertical field of view
//!
//! [materials.white]
//! type = "diffuse"
//! rgb = [0.75, 0.75, 0.75]  # albedo, each component in [0, 1]
//! [materials.chrome]
//! type = "mirror"
//! [materials.glass]
//! type = "glass"
//! ior = 1.5
//!
//! [[quad]]                  # parallelogram corner + s·edge_u + t·edge_v, s,t in [0,1]
//! corner = [0, 0, 0]
//! edge_u = [1, 0, 0]
//! edge_v = [0, 0, 1]
//! material = "white"
//!
//! [[sphere]]
//! center = [0.5, 0.2, 0.5]
//! radius = 0.2
//! material = "glass"
//!
//! [light]                   # emits on the side of normalize(edge_u × edge_v)
//! corner = [0.4, 0.99, 0.4]
//! edge_u = [0.2, 0, 0]
//! edge_v = [0, 0, 0.2]
//! power = [10, 10, 10]      # total emitted flux per channel
//! ```

use super::error::{Error, Result};
use super::scene_scale;
use glam::Vec3;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

/// The ray epsilon of a unit-sized scene (see [`Scene::epsilon`]).
pub const RAY_EPSILON: f32 = super::scene_scale::RAY_EPSILON_REL;

/// A ray; `dir` is unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
    /// Smallest ray parameter accepted as a hit, and the distance a spawned ray's
    /// origin is pushed off its surface, so a ray never re-hits the surface it
    /// leaves: the scene's [`Scene::epsilon`].
    pub eps: f32,
}

impl Ray {
    /// A ray leaving surface point `pos` (geometric normal `normal`, either
    /// orientation) in direction `dir`: the origin is pushed off the surface to the
    /// side `dir` goes to, which is what keeps refracted rays from re-hitting the
    /// interface they just crossed.
    pub fn spawn(pos: Vec3, normal: Vec3, dir: Vec3, eps: f32) -> Ray {
        let side = if dir.dot(normal) >= 0.0 {
            normal
        } else {
            -normal
        };
        Ray {
            origin: pos + side * eps,
            dir,
            eps,
        }
    }

    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// How a surface scatters light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Lambertian reflector with the given albedo per channel.
    Diffuse { albedo: Vec3 },
    /// Perfect specular reflector.
    Mirror,
    /// Smooth dielectric with index of refraction `ior` (outside is vacuum).
    Glass { ior: f32 },
}

/// A parallelogram `corner + s·edge_u + t·edge_v`, `s, t ∈ [0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quad {
    pub corner: Vec3,
    pub edge_u: Vec3,
    pub edge_v: Vec3,
    /// normalize(edge_u × edge_v).
    pub normal: Vec3,
    /// (edge_u × edge_v) / |edge_u × edge_v|², which turns a hit offset into the
    /// (s, t) coordinates with two cross products (no 2x2 solve per hit).
    w: Vec3,
    pub area: f32,
}

impl Quad {
    /// `None` for a degenerate (zero-area or non-finite) parallelogram.
    pub fn new(corner: Vec3, edge_u: Vec3, edge_v: Vec3) -> Option<Quad> {
        // In f64: |u × v|² is the fourth power of the scene's size, which overflows
        // f32 beyond about 4e9 and underflows below about 1e-10 (scene_scale).
        let (u, v) = (edge_u.as_dvec3(), edge_v.as_dvec3());
        let n = u.cross(v);
        let area = n.length();
        // Relative test: an area tiny compared with the edge lengths is a sliver
        // whose normal is numerical noise.
        if !area.is_finite() || area <= 1e-6 * u.length() * v.length() {
            return None;
        }
        Some(Quad {
            corner,
            edge_u,
            edge_v,
            normal: (n / area).as_vec3(),
            w: (n / n.length_squared()).as_vec3(),
            area: area as f32,
        })
    }

    /// Ray parameter of the hit in `(ray.eps, t_max)`, if any.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let denom = self.normal.dot(ray.dir);
        // Parallel rays never hit (a grazing hit on a zero-thickness quad has no
        // meaningful shading anyway).
        if denom.abs() < 1e-9 {
            return None;
        }
        let t = self.normal.dot(self.corner - ray.origin) / denom;
        if !(t > ray.eps && t < t_max) {
            return None;
        }
        let offset = ray.at(t) - self.corner;
        let s = self.w.dot(offset.cross(self.edge_v));
        let u = self.w.dot(self.edge_u.cross(offset));
        if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&u) {
            Some(t)
        } else {
            None
        }
    }

    /// The point at parallelogram coordinates (s, t).
    pub fn point(&self, s: f32, t: f32) -> Vec3 {
        self.corner + self.edge_u * s + self.edge_v * t
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
}

impl Sphere {
    /// Nearest ray parameter of a hit in `(ray.eps, t_max)`, if any (the far
    /// root when the ray starts inside, as a refracted ray does).
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        let oc = ray.origin - self.center;
        let b = oc.dot(ray.dir);
        // Discriminant as r² − |oc − b·d|² rather than b² − (|oc|² − r²): the latter
        // cancels catastrophically when the sphere is far away relative to its size.
        let perp = oc - ray.dir * b;
        let disc = self.radius * self.radius - perp.length_squared();
        if disc < 0.0 {
            return None;
        }
        let root = disc.sqrt();
        [-b - root, -b + root]
            .into_iter()
            .find(|&t| t > ray.eps && t < t_max)
    }

    /// Outward unit normal at a surface point.
    pub fn normal_at(&self, p: Vec3) -> Vec3 {
        (p - self.center) / self.radius
    }
}

/// A one-sided parallelogram emitter: Lambertian emission of total flux `power`
/// into the half-space its quad normal points to. Its back is black.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaLight {
    pub quad: Quad,
    pub power: Vec3,
}

impl AreaLight {
    /// Emitted radiance seen from the front: a Lambertian emitter of area A and
    /// radiance L emits Φ = π·A·L, so L = Φ / (π·A).
    pub fn radiance(&self) -> Vec3 {
        self.power / (std::f32::consts::PI * self.quad.area)
    }
}

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub position: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit image-plane axes (right, and up as seen in the image).
    pub right: Vec3,
    pub up: Vec3,
    /// tan(vertical fov / 2).
    pub tan_half_fov: f32,
    /// The scene's ray epsilon, for the eye rays.
    pub eps: f32,
}

impl Camera {
    /// The eye ray through film coordinates `(fx, fy)` in `[0, 1]²` (x to the right,
    /// y downward, as image rows go) for an image of the given aspect (width/height).
    pub fn ray(&self, fx: f32, fy: f32, aspect: f32) -> Ray {
        let sx = (2.0 * fx - 1.0) * self.tan_half_fov * aspect;
        let sy = (1.0 - 2.0 * fy) * self.tan_half_fov;
        Ray {
            origin: self.position,
            dir: (self.forward + self.right * sx + self.up * sy).normalize(),
            eps: self.eps,
        }
    }
}

/// What a ray hit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Surface {
    /// A quad or sphere with this index into `Scene::materials`.
    Material(usize),
    /// The area light (either side).
    Light,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub pos: Vec3,
    /// Geometric unit normal: outward for spheres, the quad normal for quads. Not
    /// flipped toward the ray: glass needs to know whether the ray enters or leaves.
    pub normal: Vec3,
    pub surface: Surface,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    pub camera: Camera,
    pub materials: Vec<Material>,
    /// Name of each material, for messages.
    pub material_names: Vec<String>,
    /// Quads with their material index.
    pub quads: Vec<(Quad, usize)>,
    /// Spheres with their material index.
    pub spheres: Vec<(Sphere, usize)>,
    pub light: AreaLight,
    /// Ray epsilon: 1e-4 of the scene's size (`scene_scale::ray_epsilon`).
    pub epsilon: f32,
}

impl Scene {
    /// The default Cornell box (`scenes/cornell.toml`, compiled in).
    pub fn cornell_box() -> Scene {
        Scene::from_toml_str(include_str!("../../scenes/cornell.toml"), "cornell.toml")
            .expect("the built-in Cornell box scene is valid")
    }

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

    /// The nearest hit along `ray`, if any.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let mut best_t = f32::INFINITY;
        // What was hit: index into quads, spheres, or the light.
        enum Prim {
            Quad(usize),
            Sphere(usize),
            Light,
        }
        let mut best = None;
        for (i, (quad, _)) in self.quads.iter().enumerate() {
            if let Some(t) = quad.intersect(ray, best_t) {
                best_t = t;
                best = Some(Prim::Quad(i));
            }
        }
        for (i, (sphere, _)) in self.spheres.iter().enumerate() {
            if let Some(t) = sphere.intersect(ray, best_t) {
                best_t = t;
                best = Some(Prim::Sphere(i));
            }
        }
        if let Some(t) = self.light.quad.intersect(ray, best_t) {
            best_t = t;
            best = Some(Prim::Light);
        }
        let pos = ray.at(best_t);
        let (normal, surface) = match best? {
            Prim::Quad(i) => (self.quads[i].0.normal, Surface::Material(self.quads[i].1)),
            Prim::Sphere(i) => (
                self.spheres[i].0.normal_at(pos),
                Surface::Material(self.spheres[i].1),
            ),
            Prim::Light => (self.light.quad.normal, Surface::Light),
        };
        Some(Hit {
            t: best_t,
            pos,
            normal,
            surface,
        })
    }
}

/// Mirror reflection of direction `d` about the unit normal `n` (either side).
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - n * (2.0 * d.dot(n))
}

/// Scatter a ray direction `d` at a smooth dielectric of index `ior` with geometric
/// normal `n` (outward: the side with index 1). Chooses reflection with the exact
/// unpolarized Fresnel reflectance and refraction otherwise, using the uniform
/// sample `xi`; since the choice probability equals the Fresnel weight, the
/// carried power / throughput stays unchanged (pbrt's "specular" sampling).
///
/// Radiance crossing an interface scales by (η_t/η_i)², but an eye path enters
/// and leaves closed glass objects, so the factors cancel and we omit them; photon
/// power (flux) is not scaled at all.
pub fn glass_scatter(d: Vec3, n: Vec3, ior: f32, xi: f32) -> Vec3 {
    let mut cos_i = -d.dot(n);
    // Relative index η = η_i / η_t and the normal on the incident side.
    let (eta, n_incident) = if cos_i > 0.0 {
        (1.0 / ior, n)
    } else {
        cos_i = -cos_i;
        (ior, -n)
    };
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        // Total internal reflection.
        return reflect(d, n_incident);
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_s = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_p = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let reflectance = 0.5 * (r_s * r_s + r_p * r_p);
    if xi < reflectance {
        reflect(d, n_incident)
    } else {
        (d * eta + n_incident * (eta * cos_i - cos_t)).normalize()
    }
}

/// A cosine-weighted direction in the hemisphere around unit `n` from two uniform
/// samples (Malley's method: uniform on the disk, projected up).
pub fn cosine_direction(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    let r = u1.sqrt();
    let phi = 2.0 * std::f32::consts::PI * u2;
    let (t, b) = n.any_orthonormal_pair();
    let z = (1.0 - u1).max(0.0).sqrt();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * z).normalize()
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
    fn sphere_intersection_matches_analytic_roots() {
        let s = Sphere {
            center: Vec3::new(1.0, 2.0, 3.0),
            radius: 2.0,
        };
        // Ray along +x offset by 1 in y: hits at x = 1 ± sqrt(4 − 1).
        let ray = Ray {
            origin: Vec3::new(-10.0, 3.0, 3.0),
            dir: Vec3::X,
            eps: RAY_EPSILON,
        };
        let t = s.intersect(&ray, f32::INFINITY).unwrap();
        let expected = 11.0 - 3f32.sqrt();
        assert!((t - expected).abs() < 1e-5, "{t} vs {expected}");
        // From inside, the far root.
        let inside = Ray {
            origin: Vec3::new(1.0, 2.0, 3.0),
            dir: Vec3::new(0.0, 0.0, -1.0),
            eps: RAY_EPSILON,
        };
        assert!((s.intersect(&inside, f32::INFINITY).unwrap() - 2.0).abs() < 1e-6);
        // Miss: offset 2.01 > radius.
        let miss = Ray {
            origin: Vec3::new(-10.0, 4.01, 3.0),
            dir: Vec3::X,
            eps: RAY_EPSILON,
        };
        assert_eq!(s.intersect(&miss, f32::INFINITY), None);
        // Behind the origin.
        let behind = Ray {
            origin: Vec3::new(10.0, 2.0, 3.0),
            dir: Vec3::X,
            eps: RAY_EPSILON,
        };
        assert_eq!(s.intersect(&behind, f32::INFINITY), None);
        // t_max clips.
        assert_eq!(s.intersect(&ray, 5.0), None);
        // Normal at the top is +y.
        assert!((s.normal_at(Vec3::new(1.0, 4.0, 3.0)) - Vec3::Y).length() < 1e-6);
    }

    #[test]
    fn quad_intersection_matches_analytic_cases() {
        // Slanted parallelogram in the plane z = 2: corner (0,0,2), u = (2,0,0),
        // v = (1,1,0): points (s·2 + t, t, 2).
        let q = Quad::new(
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        )
        .unwrap();
        assert!((q.area - 2.0).abs() < 1e-6);
        assert_eq!(q.normal, Vec3::Z);
        let down = |x: f32, y: f32| Ray {
            origin: Vec3::new(x, y, 5.0),
            dir: -Vec3::Z,
            eps: RAY_EPSILON,
        };
        // (2.5, 0.5): t = 0.5, s = 1.0 → inside; distance 3.
        assert!((q.intersect(&down(2.5, 0.5), f32::INFINITY).unwrap() - 3.0).abs() < 1e-6);
        // (0.2, 0.5): s = (0.2 − 0.5)/2 < 0 → outside the slanted edge.
        assert_eq!(q.intersect(&down(0.2, 0.5), f32::INFINITY), None);
        // (1.0, 1.1): t > 1 → outside.
        assert_eq!(q.intersect(&down(1.0, 1.1), f32::INFINITY), None);
        // Oblique ray from below hits at the same point regardless of side.
        let dir = Vec3::new(1.0, 0.0, 1.0).normalize();
        let oblique = Ray {
            origin: Vec3::new(0.5, 0.5, 0.0),
            dir,
            eps: RAY_EPSILON,
        };
        let t = q.intersect(&oblique, f32::INFINITY).unwrap();
        assert!((t - 2.0 * 2f32.sqrt()).abs() < 1e-5);
        // Parallel ray misses.
        let parallel = Ray {
            origin: Vec3::new(0.0, 0.5, 2.0),
            dir: Vec3::X,
            eps: RAY_EPSILON,
        };
        assert_eq!(q.intersect(&parallel, f32::INFINITY), None);
        assert!(Quad::new(Vec3::ZERO, Vec3::X, Vec3::X * 2.0).is_none());
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

    #[test]
    fn glass_scatter_obeys_snell_and_total_internal_reflection() {
        let n = Vec3::Y;
        // 45° incidence from outside, xi = 1 forces refraction: sin θt = sin 45° / 1.5.
        let d = Vec3::new(1.0, -1.0, 0.0).normalize();
        let t = glass_scatter(d, n, 1.5, 1.0);
        let sin_t = t.x;
        assert!((sin_t - (0.5f32.sqrt() / 1.5)).abs() < 1e-5);
        assert!(t.y < 0.0);
        // xi = 0 forces reflection.
        let r = glass_scatter(d, n, 1.5, 0.0);
        assert!((r - Vec3::new(d.x, -d.y, 0.0)).length() < 1e-6);
        // From inside at 60° (> critical 41.8°): always reflected back inside.
        let d_in = Vec3::new(60f32.to_radians().sin(), 60f32.to_radians().cos(), 0.0);
        let tir = glass_scatter(d_in, n, 1.5, 1.0);
        assert!((tir - Vec3::new(d_in.x, -d_in.y, 0.0)).length() < 1e-6);
    }
}
