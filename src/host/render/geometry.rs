//! Scene geometry: rays, the primitives (parallelogram, sphere, area light), the
//! pinhole camera and the scattering of mirrors, glass and diffuse surfaces. f32
//! (glam `Vec3`) throughout; every ray carries the scene's epsilon (1e-4 of its size,
//! `scene_scale`).

use glam::Vec3;

/// The ray epsilon of a unit-sized scene (see [`Scene::epsilon`](crate::host::render::scene::Scene::epsilon)).
pub const RAY_EPSILON: f32 = crate::host::render::scene_scale::RAY_EPSILON_REL;

/// A ray; `dir` is unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
    /// Smallest ray parameter accepted as a hit, and the distance a spawned ray's
    /// origin is pushed off its surface, so a ray never re-hits the surface it
    /// leaves: the scene's [`Scene::epsilon`](crate::host::render::scene::Scene::epsilon).
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

/// The surface normal `n` turned to the side a ray of direction `d` arrived from
/// (a diffuse bounce, a gather and a shading point all leave on that side).
pub fn facing(n: Vec3, d: Vec3) -> Vec3 {
    if n.dot(d) < 0.0 {
        n
    } else {
        -n
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

#[cfg(test)]
mod tests {
    use super::*;

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
