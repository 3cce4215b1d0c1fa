//! The objects of Veenstra & Ahuja's Figs. 5–11, made by small private generators: exact voxel-centre
//! tests turned into rays and stacked. They stand in for the solids (quadrics, CSG) and tree Boolean
//! modules being built alongside, which will replace them.

use crate::build::stack;
use crate::rays::{Normal, Ray, RaySet};
use crate::tree::Octree;

/// A figure's object: its name, the paper's figure number and its inside test on the unit cube
/// (`p` is a voxel centre scaled to `[0, 1]^3`).
pub struct Shape {
    /// File-name part, e.g. `cylinder`.
    pub name: &'static str,
    /// The paper's figure number.
    pub figure: u32,
    /// What it is, for the tables.
    pub description: &'static str,
    /// The inside test.
    pub inside: fn([f64; 3]) -> bool,
}

fn cylinder(p: [f64; 3]) -> bool {
    let (x, y) = (p[0] - 0.5, p[1] - 0.5);
    x * x + y * y <= 0.4 * 0.4 && (0.1..=0.9).contains(&p[2])
}

fn cone(p: [f64; 3]) -> bool {
    let (x, y) = (p[0] - 0.5, p[1] - 0.5);
    let r = 0.42 * (0.9 - p[2]) / 0.8;
    p[2] >= 0.1 && r > 0.0 && x * x + y * y <= r * r
}

fn sphere(p: [f64; 3]) -> bool {
    let d: f64 = p.iter().map(|c| (c - 0.5) * (c - 0.5)).sum();
    d <= 0.45 * 0.45
}

fn pyramid(p: [f64; 3]) -> bool {
    let half = 0.42 * (0.88 - p[2]) / 0.78;
    p[2] >= 0.1 && (p[0] - 0.5).abs() <= half && (p[1] - 0.5).abs() <= half
}

/// Self-occluding: a torus lying in the x-y plane, crossed by a bar through its hole.
fn self_occluding(p: [f64; 3]) -> bool {
    let (x, y, z) = (p[0] - 0.5, p[1] - 0.5, p[2] - 0.5);
    let ring = ((x * x + y * y).sqrt() - 0.3).powi(2) + z * z <= 0.11 * 0.11;
    let bar = x.abs() <= 0.06 && z.abs() <= 0.06 && y.abs() <= 0.46;
    ring || bar
}

fn diamond(p: [f64; 3]) -> bool {
    p.iter().map(|c| (c - 0.5).abs()).sum::<f64>() <= 0.46
}

/// The coffee cup's three silhouettes, 16 × 16 pixels, top row first. Front: looking along y (x across,
/// z up) — the body and a ring handle; side: looking along x (y across, z up) — the body; top: looking
/// down z (x across, y up) — a disc and the handle's bar.
const CUP_FRONT: [&str; 16] = [
    "................",
    "................",
    "..#########.....",
    "..############..",
    "..#########..#..",
    "..#########..#..",
    "..#########..#..",
    "..############..",
    "..#########.....",
    "..#########.....",
    "...#######......",
    "...#######......",
    "....#####.......",
    "................",
    "................",
    "................",
];
const CUP_SIDE: [&str; 16] = [
    "................",
    "................",
    "..#########.....",
    "..#########.....",
    "..#########.....",
    "..#########.....",
    "..#########.....",
    "..#########.....",
    "..#########.....",
    "..#########.....",
    "...#######......",
    "...#######......",
    "....#####.......",
    "................",
    "................",
    "................",
];
const CUP_TOP: [&str; 16] = [
    "................",
    "................",
    "................",
    "................",
    "................",
    "....#####.......",
    "...#######......",
    "..#########.....",
    "..############..",
    "..############..",
    "..############..",
    "..#########.....",
    "...#######......",
    "....#####.......",
    "................",
    "................",
];

fn pixel(image: &[&str; 16], across: f64, up: f64) -> bool {
    let col = ((across * 16.0).floor() as usize).min(15);
    let row = 15 - ((up * 16.0).floor() as usize).min(15);
    image[row].as_bytes()[col] == b'#'
}

/// The cup: the intersection of the three silhouettes extruded along their viewing directions.
fn coffee_cup(p: [f64; 3]) -> bool {
    pixel(&CUP_FRONT, p[0], p[2]) && pixel(&CUP_SIDE, p[1], p[2]) && pixel(&CUP_TOP, p[0], p[1])
}

/// The shapes of Figs. 5–11 in figure order.
pub fn shapes() -> Vec<Shape> {
    vec![
        Shape {
            name: "cylinder",
            figure: 5,
            description: "cylinder (radius 0.4 U, height 0.8 U)",
            inside: cylinder,
        },
        Shape {
            name: "cone",
            figure: 6,
            description: "cone (base radius 0.42 U, height 0.8 U)",
            inside: cone,
        },
        Shape {
            name: "sphere",
            figure: 7,
            description: "sphere (radius 0.45 U)",
            inside: sphere,
        },
        Shape {
            name: "pyramid",
            figure: 8,
            description: "square pyramid (base 0.84 U, height 0.78 U)",
            inside: pyramid,
        },
        Shape {
            name: "coffee_cup",
            figure: 9,
            description: "coffee cup: three 16×16 silhouettes extruded and intersected",
            inside: coffee_cup,
        },
        Shape {
            name: "self_occluding",
            figure: 10,
            description: "torus crossed by a bar through its hole (self-occluding)",
            inside: self_occluding,
        },
        Shape {
            name: "diamond",
            figure: 11,
            description: "octahedron |x|+|y|+|z| ≤ 0.46 U: a diamond silhouette from every face",
            inside: diamond,
        },
    ]
}

/// The rays of a shape at `level`: each column's voxels whose centres are inside, as runs.
pub fn shape_rays(shape: &Shape, level: u32) -> Result<RaySet<3>, String> {
    rays_of(level, shape.inside, None::<fn([f64; 3]) -> [f64; 3]>)
}

/// The rays of an inside test, with normals from `gradient` at run ends when given (unit coordinates).
pub fn rays_of(
    level: u32,
    inside: fn([f64; 3]) -> bool,
    gradient: Option<impl Fn([f64; 3]) -> [f64; 3]>,
) -> Result<RaySet<3>, String> {
    let side = 1u32 << level;
    let unit = |v: u32| (f64::from(v) + 0.5) / f64::from(side);
    let mut runs = Vec::new();
    let mut normals = Vec::new();
    for x in 0..side {
        for y in 0..side {
            let mut start: Option<u32> = None;
            for z in 0..=side {
                let is_in = z < side && inside([unit(x), unit(y), unit(z)]);
                match (is_in, start) {
                    (true, None) => start = Some(z),
                    (false, Some(z1)) => {
                        runs.push(Ray::new([x, y, z1], z));
                        if let Some(g) = &gradient {
                            let at = |zz: f64| -> Normal<3> {
                                g([unit(x), unit(y), zz / f64::from(side)]).map(|c| c as f32)
                            };
                            normals.push([at(f64::from(z1)), at(f64::from(z))]);
                        }
                        start = None;
                    }
                    _ => {}
                }
            }
        }
    }
    let set = if gradient.is_some() {
        RaySet::from_rays_with_normals(level, runs.into_iter().zip(normals))
    } else {
        RaySet::from_rays(level, runs)
    };
    set.map_err(|e| e.to_string())
}

/// The sphere with its exact surface normals carried by the rays (for smooth shading).
pub fn sphere_with_normals(level: u32) -> Result<(RaySet<3>, Octree), String> {
    let rays = rays_of(level, sphere, Some(|p: [f64; 3]| p.map(|c| c - 0.5)))?;
    let tree = stack(&rays);
    Ok((rays, tree))
}

/// A 4-D object: a ball of radius U/5 moving along x from U/4 to 3U/4 (and rising along z) while time,
/// the fourth axis, goes from 0 to U. Rays run along time: each voxel's run is when the ball covers it.
pub fn moving_ball(level: u32) -> Result<RaySet<4>, String> {
    let side = 1u32 << level;
    let u = f64::from(side);
    let mut runs = Vec::new();
    for x in 0..side {
        for y in 0..side {
            for z in 0..side {
                let mut start: Option<u32> = None;
                for t in 0..=side {
                    let inside = t < side && {
                        let s = (f64::from(t) + 0.5) / u;
                        let c = [u * (0.25 + 0.5 * s), u * 0.5, u * (0.35 + 0.3 * s)];
                        let d: f64 = [x, y, z]
                            .iter()
                            .zip(c)
                            .map(|(&v, c)| (f64::from(v) + 0.5 - c).powi(2))
                            .sum();
                        d <= (u / 5.0).powi(2)
                    };
                    match (inside, start) {
                        (true, None) => start = Some(t),
                        (false, Some(t1)) => {
                            runs.push(Ray::new([x, y, z, t1], t));
                            start = None;
                        }
                        _ => {}
                    }
                }
            }
        }
    }
    RaySet::from_rays(level, runs).map_err(|e| e.to_string())
}
