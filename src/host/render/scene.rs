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

pub use crate::host::render::geometry::{
    cosine_direction, facing, glass_scatter, reflect, AreaLight, Camera, Hit, Material, Quad, Ray,
    Sphere, Surface, RAY_EPSILON,
};

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
        Scene::from_toml_str(include_str!("../../../scenes/cornell.toml"), "cornell.toml")
            .expect("the built-in Cornell box scene is valid")
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
