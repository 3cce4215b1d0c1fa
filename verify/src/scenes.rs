//! Synthetic scenes for maps, scanned exactly: a room seen from inside (an axis-aligned box), boxes
//! standing in it, and a person (a box) walking across it, each scan a spinning multi-beam sensor's rays
//! cut at the first surface they meet (slab intersections, in `f64`).
//!
//! ```
//! use ktree_verify::scenes::WalkingPerson;
//! let scene = WalkingPerson::new(8);
//! let scan = scene.scan(0, 90, 16);
//! assert_eq!(scan.points.len(), 90 * 16);
//! // Every point is on the room's walls or on a box in it: inside the room.
//! assert!(scan.points.iter().all(|p| scene.room.contains(*p, 1e-4)));
//! ```

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// The lower corner.
    pub lo: [f64; 3],
    /// The upper corner.
    pub hi: [f64; 3],
}

impl Aabb {
    /// Whether a point is in the box grown by `slack` on every side.
    pub fn contains(&self, p: [f32; 3], slack: f64) -> bool {
        (0..3).all(|a| {
            let c = f64::from(p[a]);
            c >= self.lo[a] - slack && c <= self.hi[a] + slack
        })
    }

    /// The parameter at which the ray `o + t·d` enters the box from outside (`None`: it misses, or
    /// starts inside).
    fn entry(&self, o: [f64; 3], d: [f64; 3]) -> Option<f64> {
        let (mut near, mut far) = (f64::NEG_INFINITY, f64::INFINITY);
        for a in 0..3 {
            if d[a] == 0.0 {
                if o[a] < self.lo[a] || o[a] > self.hi[a] {
                    return None;
                }
                continue;
            }
            let (t0, t1) = ((self.lo[a] - o[a]) / d[a], (self.hi[a] - o[a]) / d[a]);
            near = near.max(t0.min(t1));
            far = far.min(t0.max(t1));
        }
        (near <= far && near > 0.0).then_some(near)
    }

    /// The parameter at which a ray from inside the box leaves it.
    fn exit(&self, o: [f64; 3], d: [f64; 3]) -> f64 {
        (0..3)
            .filter(|&a| d[a] != 0.0)
            .map(|a| {
                let wall = if d[a] > 0.0 { self.hi[a] } else { self.lo[a] };
                (wall - o[a]) / d[a]
            })
            .fold(f64::INFINITY, f64::min)
    }
}

/// One scan: the points in world coordinates and the sensor's origin.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneScan {
    /// Where the rays ended, on the first surface each met.
    pub points: Vec<[f32; 3]>,
    /// The sensor's position.
    pub origin: [f32; 3],
}

/// A room of 8 × 6 × 2.5 m with a table and a cupboard, a sensor standing near one wall, and a person
/// (0.5 × 0.3 × 1.75 m) walking along the room's length in front of the sensor over `steps` steps. The
/// walls lie off the 5 and 10 cm grids, so no point falls on a boundary between voxels.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkingPerson {
    /// The room (its inside).
    pub room: Aabb,
    /// The boxes that never move.
    pub furniture: Vec<Aabb>,
    /// The sensor's position.
    pub sensor: [f64; 3],
    /// The number of steps of the walk.
    pub steps: usize,
}

impl WalkingPerson {
    /// The scene with a walk of `steps` steps (at least 2).
    pub fn new(steps: usize) -> Self {
        Self {
            room: Aabb {
                lo: [-3.97, -2.97, 0.03],
                hi: [3.97, 2.97, 2.47],
            },
            furniture: vec![
                Aabb {
                    lo: [1.13, 0.91, 0.03],
                    hi: [2.33, 1.71, 0.76],
                },
                Aabb {
                    lo: [-3.97, -2.97, 0.03],
                    hi: [-3.21, -1.83, 1.92],
                },
            ],
            sensor: [0.02, 2.01, 1.23],
            steps: steps.max(2),
        }
    }

    /// The person's box at step `t`: walking from x = −2.5 to x = 2.5 at y = −0.8.
    pub fn person(&self, t: usize) -> Aabb {
        let x = -2.5 + 5.0 * t as f64 / (self.steps - 1) as f64;
        Aabb {
            lo: [x - 0.25, -0.95, 0.03],
            hi: [x + 0.25, -0.65, 1.78],
        }
    }

    /// The scan at step `t`: `azimuths` rays around the vertical axis times `beams` rays between 40°
    /// below and 20° above the horizon, each cut at the first surface it meets.
    pub fn scan(&self, t: usize, azimuths: usize, beams: usize) -> SceneScan {
        let person = self.person(t);
        let o = self.sensor;
        let mut points = Vec::with_capacity(azimuths * beams);
        for b in 0..beams {
            let elevation = (-40.0 + 60.0 * (b as f64 + 0.5) / beams as f64).to_radians();
            for a in 0..azimuths {
                let azimuth = (360.0 * (a as f64 + 0.37) / azimuths as f64).to_radians();
                let d = [
                    elevation.cos() * azimuth.cos(),
                    elevation.cos() * azimuth.sin(),
                    elevation.sin(),
                ];
                let t_hit = self
                    .furniture
                    .iter()
                    .chain([&person])
                    .filter_map(|b| b.entry(o, d))
                    .fold(self.room.exit(o, d), f64::min);
                points.push(std::array::from_fn(|i| (o[i] + t_hit * d[i]) as f32));
            }
        }
        SceneScan {
            points,
            origin: o.map(|c| c as f32),
        }
    }
}
