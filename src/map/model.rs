//! The sensor model of an occupancy map: how much one hit or one miss moves a voxel's log-odds, where the
//! log-odds are clamped, and from which value a voxel counts as occupied — OctoMap's model and defaults.

/// The log-odds `ln(p / (1 − p))` of a probability, rounded to `f32` as OctoMap stores it.
///
/// ```
/// use ktree::map::log_odds;
/// assert_eq!(log_odds(0.5), 0.0);
/// assert!((log_odds(0.7) - 0.8472979).abs() < 1e-6);
/// ```
pub fn log_odds(probability: f64) -> f32 {
    (probability / (1.0 - probability)).ln() as f32
}

/// The probability of log-odds `l`.
pub fn probability(l: f32) -> f64 {
    1.0 - 1.0 / (1.0 + f64::from(l).exp())
}

/// How a voxel's log-odds change with each observation: a hit adds [`hit`](Self::hit), a miss adds
/// [`miss`](Self::miss), in `f32`, and the sum is clamped to `[clamp_min, clamp_max]`; a voxel whose
/// log-odds are at least [`occupied`](Self::occupied) is occupied, below it free.
///
/// The defaults are OctoMap's: hit probability 0.7, miss 0.4, clamping to [0.1192, 0.971], occupied from
/// 0.5.
///
/// ```
/// use ktree::map::SensorModel;
/// let model = SensorModel::default();
/// assert_eq!(model.update(0.0, true), model.hit);
/// // Many misses stop at the lower clamp.
/// let mut l = 0.0;
/// for _ in 0..100 {
///     l = model.update(l, false);
/// }
/// assert_eq!(l, model.clamp_min);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorModel {
    /// The log-odds a hit adds (OctoMap's `prob_hit_log`).
    pub hit: f32,
    /// The log-odds a miss adds (negative; OctoMap's `prob_miss_log`).
    pub miss: f32,
    /// The lowest log-odds a voxel keeps.
    pub clamp_min: f32,
    /// The highest log-odds a voxel keeps.
    pub clamp_max: f32,
    /// The log-odds from which a voxel is occupied.
    pub occupied: f32,
}

impl Default for SensorModel {
    fn default() -> Self {
        Self::from_probabilities(0.7, 0.4, 0.1192, 0.971, 0.5)
    }
}

impl SensorModel {
    /// The model of these probabilities: of a hit, of a miss, the two clamps and the occupancy threshold.
    pub fn from_probabilities(
        hit: f64,
        miss: f64,
        clamp_min: f64,
        clamp_max: f64,
        occupied: f64,
    ) -> Self {
        Self {
            hit: log_odds(hit),
            miss: log_odds(miss),
            clamp_min: log_odds(clamp_min),
            clamp_max: log_odds(clamp_max),
            occupied: log_odds(occupied),
        }
    }

    /// Why the model cannot make a map, if it cannot: a value that is not finite, a hit that does not
    /// raise the odds or a miss that does not lower them, clamps out of order.
    pub fn check(&self) -> Result<(), String> {
        let all = [
            self.hit,
            self.miss,
            self.clamp_min,
            self.clamp_max,
            self.occupied,
        ];
        if all.iter().any(|v| !v.is_finite()) {
            return Err(format!(
                "every probability of the sensor model must be strictly between 0 and 1 (log-odds {all:?})"
            ));
        }
        if self.hit <= 0.0 || self.miss >= 0.0 {
            return Err(format!(
                "a hit must have a probability above 0.5 and a miss below (log-odds {} and {})",
                self.hit, self.miss
            ));
        }
        if self.clamp_min > self.clamp_max {
            return Err(format!(
                "the lower clamp (log-odds {}) is above the upper ({})",
                self.clamp_min, self.clamp_max
            ));
        }
        Ok(())
    }

    /// The log-odds `l` after one hit (`hit`) or miss: OctoMap's `updateNodeLogOdds`, in `f32`.
    #[inline]
    pub fn update(&self, l: f32, hit: bool) -> f32 {
        let l = l + if hit { self.hit } else { self.miss };
        if l < self.clamp_min {
            self.clamp_min
        } else if l > self.clamp_max {
            self.clamp_max
        } else {
            l
        }
    }

    /// Whether log-odds `l` are occupied (OctoMap's `isNodeOccupied`: at least the threshold).
    #[inline]
    pub fn is_occupied(&self, l: f32) -> bool {
        l >= self.occupied
    }
}
