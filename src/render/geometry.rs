//! Vectors, rays, spheres, axis-aligned boxes, a pinhole camera and the Cornell-box scene.

use std::ops::{Add, Mul, Neg, Sub};

/// A point or direction in 3D.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vec3 {
    /// x (right).
    pub x: f64,
    /// y (up).
    pub y: f64,
    /// z (into the scene).
    pub z: f64,
}

impl Vec3 {
    /// `(x, y, z)`.
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Self { x, y, z }
    }
    /// The dot product.
    pub fn dot(self, o: Self) -> f64 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    /// The cross product.
    pub fn cross(self, o: Self) -> Self {
        Self::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }
    /// The unit vector along `self`.
    pub fn normalized(self) -> Self {
        self * (1.0 / self.dot(self).sqrt())
    }
    fn axis(self, a: usize) -> f64 {
        [self.x, self.y, self.z][a]
    }
}

impl Add for Vec3 {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl Sub for Vec3 {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl Mul<f64> for Vec3 {
    type Output = Self;
    fn mul(self, s: f64) -> Self {
        Self::new(self.x * s, self.y * s, self.z * s)
    }
}

impl Neg for Vec3 {
    type Output = Self;
    fn neg(self) -> Self {
        Self::new(-self.x, -self.y, -self.z)
    }
}

/// A half-line `origin + t direction`, `t > 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Where it starts.
    pub origin: Vec3,
    /// Its direction (unit length).
    pub direction: Vec3,
}

/// A surface the renderer can hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// A sphere.
    Sphere {
        /// Centre.
        centre: Vec3,
        /// Radius.
        radius: f64,
    },
    /// An axis-aligned box `[min, max]`.
    AxisBox {
        /// The corner with the smallest coordinates.
        min: Vec3,
        /// The corner with the largest coordinates.
        max: Vec3,
    },
}

impl Shape {
    /// The nearest intersection with `t` in `(0, t_max)`: its distance and the unit normal
    /// facing the ray.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<(f64, Vec3)> {
        match *self {
            Shape::Sphere { centre, radius } => {
                let oc = ray.origin - centre;
                let b = oc.dot(ray.direction);
                let disc = b * b - (oc.dot(oc) - radius * radius);
                if disc < 0.0 {
                    return None;
                }
                let root = disc.sqrt();
                let t = [-b - root, -b + root]
                    .into_iter()
                    .find(|&t| t > 0.0 && t < t_max)?;
                let normal = (ray.origin + ray.direction * t - centre) * (1.0 / radius);
                Some((t, facing(normal, ray.direction)))
            }
            Shape::AxisBox { min, max } => {
                let (mut near, mut far) = (f64::NEG_INFINITY, f64::INFINITY);
                let (mut near_axis, mut far_axis) = (0, 0);
                for a in 0..3 {
                    let inv = 1.0 / ray.direction.axis(a);
                    let t0 = (min.axis(a) - ray.origin.axis(a)) * inv;
                    let t1 = (max.axis(a) - ray.origin.axis(a)) * inv;
                    let (lo, hi) = if t0 < t1 { (t0, t1) } else { (t1, t0) };
                    if lo > near {
                        (near, near_axis) = (lo, a);
                    }
                    if hi < far {
                        (far, far_axis) = (hi, a);
                    }
                }
                if near > far {
                    return None;
                }
                let (t, axis) = if near > 0.0 {
                    (near, near_axis)
                } else {
                    (far, far_axis)
                };
                if t <= 0.0 || t >= t_max {
                    return None;
                }
                let mut normal = [0.0; 3];
                normal[axis] = 1.0;
                Some((
                    t,
                    facing(Vec3::new(normal[0], normal[1], normal[2]), ray.direction),
                ))
            }
        }
    }
}

impl Shape {
    /// The distance from `p` to the nearest point of the shape (0 inside it).
    fn distance_from(&self, p: Vec3) -> f64 {
        match *self {
            Shape::Sphere { centre, radius } => {
                let r = p - centre;
                (r.dot(r).sqrt() - radius).max(0.0)
            }
            Shape::AxisBox { min, max } => {
                let gaps = (0..3).map(|a| {
                    let gap = (min.axis(a) - p.axis(a))
                        .max(p.axis(a) - max.axis(a))
                        .max(0.0);
                    gap * gap
                });
                gaps.sum::<f64>().sqrt()
            }
        }
    }

    /// Whether the ray meets the shape at some `t` in `(0, t_max)`: the decision of
    /// [`intersect`](Self::intersect), to the same bits, without the normal and with the
    /// direction's reciprocals computed once per ray by the caller.
    fn blocks(&self, ray: &Ray, inverse: [f64; 3], t_max: f64) -> bool {
        match *self {
            Shape::Sphere { .. } => self.intersect(ray, t_max).is_some(),
            Shape::AxisBox { min, max } => {
                let (mut near, mut far) = (f64::NEG_INFINITY, f64::INFINITY);
                for (a, &inv) in inverse.iter().enumerate() {
                    let t0 = (min.axis(a) - ray.origin.axis(a)) * inv;
                    let t1 = (max.axis(a) - ray.origin.axis(a)) * inv;
                    let (lo, hi) = if t0 < t1 { (t0, t1) } else { (t1, t0) };
                    if lo > near {
                        near = lo;
                    }
                    if hi < far {
                        far = hi;
                    }
                }
                if near > far {
                    return false;
                }
                let t = if near > 0.0 { near } else { far };
                t > 0.0 && t < t_max
            }
        }
    }
}

/// `normal` or its opposite, whichever faces against `direction`.
fn facing(normal: Vec3, direction: Vec3) -> Vec3 {
    if normal.dot(direction) > 0.0 {
        -normal
    } else {
        normal
    }
}

/// A pinhole camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// The eye.
    pub position: Vec3,
    /// Unit viewing direction.
    pub forward: Vec3,
    /// Unit vector to the right of the image.
    pub right: Vec3,
    /// Unit vector to the top of the image.
    pub up: Vec3,
    /// `tan` of half the vertical field of view.
    pub half_height: f64,
}

impl Camera {
    /// The ray through the centre of pixel `(px, py)` of a `width × height` image (row 0 at
    /// the top; square pixels).
    pub fn primary_ray(&self, px: usize, py: usize, width: usize, height: usize) -> Ray {
        let aspect = width as f64 / height as f64;
        let sx = (2.0 * (px as f64 + 0.5) / width as f64 - 1.0) * self.half_height * aspect;
        let sy = (1.0 - 2.0 * (py as f64 + 0.5) / height as f64) * self.half_height;
        Ray {
            origin: self.position,
            direction: (self.forward + self.right * sx + self.up * sy).normalized(),
        }
    }
}

/// A surface point seen by a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Where.
    pub point: Vec3,
    /// The unit normal facing the incoming ray.
    pub normal: Vec3,
}

/// Shapes and a camera.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// A name with a version, e.g. `cornell-v1`: cached references are keyed by it.
    pub name: String,
    /// Everything that can be hit or occlude.
    pub shapes: Vec<Shape>,
    /// The view.
    pub camera: Camera,
}

/// Relative and absolute margin on the distance within which a shape counts as near.
const NEAR_MARGIN: f64 = 1e-9;

/// The shapes of a scene near one point, from [`Scene::near`]: a bit per shape (every shape
/// beyond the first 64 counts as near).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NearShapes {
    mask: u64,
    beyond: bool,
}

impl NearShapes {
    /// Every shape.
    pub const ALL: Self = Self {
        mask: u64::MAX,
        beyond: true,
    };
    const BITS: usize = 64;

    fn holds(self, shape: usize) -> bool {
        if shape >= Self::BITS {
            self.beyond
        } else {
            (self.mask >> shape) & 1 == 1
        }
    }
}

impl Scene {
    /// A Cornell-box-like room `[0,1]³` open towards the camera (walls, floor and ceiling are
    /// slabs 0.1 thick), with a tall and a short block and two spheres, seen from
    /// `(0.5, 0.5, -1.2)` so that the opening fills the view.
    pub fn cornell_box() -> Self {
        let slab = |min: [f64; 3], max: [f64; 3]| Shape::AxisBox {
            min: Vec3::new(min[0], min[1], min[2]),
            max: Vec3::new(max[0], max[1], max[2]),
        };
        let shapes = vec![
            slab([-0.1, -0.1, -0.1], [1.1, 0.0, 1.1]),   // floor
            slab([-0.1, 1.0, -0.1], [1.1, 1.1, 1.1]),    // ceiling
            slab([-0.1, -0.1, 1.0], [1.1, 1.1, 1.1]),    // back wall
            slab([-0.1, -0.1, -0.1], [0.0, 1.1, 1.1]),   // left wall
            slab([1.0, -0.1, -0.1], [1.1, 1.1, 1.1]),    // right wall
            slab([0.55, 0.0, 0.5], [0.85, 0.6, 0.8]),    // tall block
            slab([0.12, 0.0, 0.25], [0.42, 0.28, 0.55]), // short block
            Shape::Sphere {
                centre: Vec3::new(0.27, 0.4, 0.4),
                radius: 0.12,
            },
            Shape::Sphere {
                centre: Vec3::new(0.7, 0.12, 0.22),
                radius: 0.12,
            },
        ];
        let camera = Camera {
            position: Vec3::new(0.5, 0.5, -1.2),
            forward: Vec3::new(0.0, 0.0, 1.0),
            right: Vec3::new(1.0, 0.0, 0.0),
            up: Vec3::new(0.0, 1.0, 0.0),
            half_height: 0.5 / 1.2,
        };
        Self {
            name: "cornell-v1".into(),
            shapes,
            camera,
        }
    }

    /// The nearest surface along `ray`, if any.
    pub fn first_hit(&self, ray: &Ray) -> Option<Hit> {
        let mut best: Option<(f64, Vec3)> = None;
        for shape in &self.shapes {
            let limit = best.map_or(f64::INFINITY, |b| b.0);
            if let Some(hit) = shape.intersect(ray, limit) {
                best = Some(hit);
            }
        }
        best.map(|(t, normal)| Hit {
            point: ray.origin + ray.direction * t,
            normal,
        })
    }

    /// Whether any surface lies along `ray` closer than `max_distance`.
    pub fn occluded(&self, ray: &Ray, max_distance: f64) -> bool {
        self.occluded_near(ray, max_distance, NearShapes::ALL)
    }

    /// The shapes that a ray from `origin` with a unit direction can meet closer than
    /// `max_distance`: those within that distance of `origin`, with a margin far above the
    /// rounding of a unit direction and of the slab tests. The others cannot block any such
    /// ray, so [`occluded_near`](Self::occluded_near) skips them and decides as
    /// [`occluded`](Self::occluded) does.
    pub fn near(&self, origin: Vec3, max_distance: f64) -> NearShapes {
        let reach = max_distance * (1.0 + NEAR_MARGIN) + NEAR_MARGIN;
        let mut mask = 0u64;
        for (i, shape) in self.shapes.iter().enumerate().take(NearShapes::BITS) {
            if shape.distance_from(origin) <= reach {
                mask |= 1 << i;
            }
        }
        NearShapes {
            mask,
            beyond: self.shapes.len() > NearShapes::BITS,
        }
    }

    /// As [`occluded`](Self::occluded) for a ray from the origin `near` was made for, testing
    /// only the shapes it holds.
    pub fn occluded_near(&self, ray: &Ray, max_distance: f64, near: NearShapes) -> bool {
        let d = ray.direction;
        let inverse = [1.0 / d.x, 1.0 / d.y, 1.0 / d.z];
        self.shapes
            .iter()
            .enumerate()
            .any(|(i, s)| near.holds(i) && s.blocks(ray, inverse, max_distance))
    }
}
