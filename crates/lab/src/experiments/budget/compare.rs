//! The budget against the fixed radii at the same speed-up: on which axis, by which measure,
//! and how far apart, trial by trial.

use serde::Serialize;

use super::super::mean_and_variance;
use super::{Point, Row, Setting};
use simlod::outcome::Obstacle;

/// A speed-up of the trade-off: on average (figure 10's), of the slowest frame as the cost
/// model predicts it, of the 99th-percentile frame measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Axis {
    Mean,
    Slowest,
    P99,
}

impl Axis {
    pub(super) const ALL: [Axis; 3] = [Axis::Mean, Axis::Slowest, Axis::P99];

    pub(super) fn of(self, p: &Point) -> f64 {
        match self {
            Axis::Mean => p.speedup,
            Axis::Slowest => p.slowest_speedup,
            Axis::P99 => p.p99_speedup,
        }
    }

    /// What the speed-up is of, in the report's tables.
    pub(super) fn name(self) -> &'static str {
        match self {
            Axis::Mean => "speed-up",
            Axis::Slowest => "speed-up of the slowest frame (cost model)",
            Axis::P99 => "speed-up of the 99th-percentile frame (measured)",
        }
    }

    /// The panel's title and its y axis.
    pub(super) fn panel(self) -> (&'static str, &'static str) {
        match self {
            Axis::Mean => ("speed on average", "speed-up over all rigid (wall time, on average)"),
            Axis::Slowest => (
                "the frame rate guaranteed",
                "speed-up of the slowest frame over all rigid's (cost model)",
            ),
            Axis::P99 => (
                "the frame rate held, measured",
                "speed-up of the 99th-percentile frame (measured wall time)",
            ),
        }
    }

    /// The figure of its trade-off on figure 10's count.
    pub(super) fn figure(self) -> &'static str {
        match self {
            Axis::Mean => "budget.png",
            Axis::Slowest => "budget-slowest.png",
            Axis::P99 => "budget-p99.png",
        }
    }

    /// The key of the budgets set against the fixed radii in the JSON.
    pub(super) fn key(self) -> &'static str {
        match self {
            Axis::Mean => "against_fixed",
            Axis::Slowest => "against_fixed_slowest",
            Axis::P99 => "against_fixed_p99",
        }
    }
}

/// What an outcome's change from all rigid is measured by.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Measure {
    /// Figure 10's: the change in creatures that collided with the puck or a wall, with its sign.
    Count,
    /// The change in creatures that hit the puck and in those that hit a wall, each without its
    /// sign, added: two errors of opposite sign do not cancel.
    ByObstacle,
}

impl Measure {
    /// A trial's changes that the measure adds, each taken with the sign of its mean.
    pub(super) fn parts(self, r: &Row) -> Vec<f64> {
        match self {
            Measure::Count => vec![r.difference()],
            Measure::ByObstacle => vec![r.difference_with(Obstacle::Puck), r.difference_with(Obstacle::Wall)],
        }
    }

    pub(super) fn of(self, p: &Point) -> f64 {
        match self {
            Measure::Count => p.mean_difference,
            Measure::ByObstacle => p.puck_difference.0.abs() + p.wall_difference.0.abs(),
        }
    }

    /// Its standard error (by obstacle, the two parts' taken as independent).
    pub(super) fn standard_error(self, p: &Point) -> f64 {
        match self {
            Measure::Count => p.se_difference,
            Measure::ByObstacle => p.puck_difference.1.hypot(p.wall_difference.1),
        }
    }

    pub(super) fn x_label(self) -> &'static str {
        match self {
            Measure::Count => "change in creatures that hit the puck or a wall (mean, against all rigid)",
            Measure::ByObstacle => "error by obstacle: |change at the puck| + |change at the walls| (means)",
        }
    }
}

/// A budget's point against the fixed-radius curve at the same speed-up, on one measure.
#[derive(Clone, Debug, Serialize)]
pub(super) struct Comparison {
    /// The budget's change (the count's with its sign) and its standard error.
    pub(super) difference: f64,
    pub(super) se_difference: f64,
    /// The fixed-radius curve's at this speed-up, interpolated trial by trial in log speed-up
    /// between the radii on either side; beyond the fastest radius, the fastest radius's
    /// (slower than the budget: no radius reaches its speed-up).
    pub(super) fixed_difference: f64,
    pub(super) fixed_se_difference: f64,
    /// How much nearer all rigid's outcome the budget's is than the fixed radii's (negative:
    /// farther), and its standard error, both from each trial's pair of games: where the two
    /// changes have the same sign the all-rigid game cancels out of each trial's gap.
    pub(super) gap: f64,
    pub(super) se_gap: f64,
    /// The gap is over two of its standard errors.
    pub(super) nearer_beyond_2_se: bool,
}

/// A budget against the fixed-radius curve at the same speed-up.
#[derive(Clone, Debug, Serialize)]
pub(super) struct Against {
    pub(super) budget_ms: f32,
    pub(super) least_benefit_per_ms: f32,
    #[serde(skip)]
    pub(super) label: String,
    pub(super) speedup: f64,
    /// On figure 10's count.
    #[serde(flatten)]
    pub(super) count: Comparison,
    /// On the error by obstacle.
    pub(super) by_obstacle: Comparison,
    /// Faster than every radius: set against the fastest.
    pub(super) beyond_fastest_radius: bool,
}

/// Mean, standard deviation and standard error of the mean.
pub(super) fn mean_sd_se(values: &[f64]) -> (f64, f64, f64) {
    let (mean, variance) = mean_and_variance(values);
    (mean, variance.sqrt(), (variance / values.len() as f64).sqrt())
}

/// The budget's trials against the fixed radii's, interpolated trial by trial with weight `w`
/// from `lo` to `hi`, on `measure`: each part of a trial's change is taken with the sign of its
/// mean, so each side's mean is the size of its change and the gap how much smaller the
/// budget's is.
pub(super) fn compare(
    rows: &[Row],
    budget: Setting,
    (lo, hi, w): (Setting, Setting, f64),
    measure: Measure,
) -> Comparison {
    let parts = |setting: Setting| -> Vec<Vec<f64>> {
        let mut at: Vec<&Row> = rows.iter().filter(|r| r.setting == setting).collect();
        at.sort_by_key(|r| r.trial);
        at.iter().map(|r| measure.parts(r)).collect()
    };
    let (at_lo, at_hi) = (parts(lo), parts(hi));
    let fixed: Vec<Vec<f64>> = at_lo
        .iter()
        .zip(&at_hi)
        .map(|(l, h)| l.iter().zip(h).map(|(l, h)| l + w * (h - l)).collect())
        .collect();
    let budget = parts(budget);
    let signed = |trials: &[Vec<f64>]| -> (Vec<f64>, f64) {
        let n = trials.len().max(1) as f64;
        let signs: Vec<f64> = (0..trials.first().map_or(0, Vec::len))
            .map(|i| (trials.iter().map(|t| t[i]).sum::<f64>() / n).signum())
            .collect();
        let sizes = trials
            .iter()
            .map(|t| t.iter().zip(&signs).map(|(d, s)| d * s).sum())
            .collect();
        // The count keeps its sign, as figure 10 plots it.
        (
            sizes,
            match measure {
                Measure::Count => signs.first().copied().unwrap_or(1.0),
                Measure::ByObstacle => 1.0,
            },
        )
    };
    let ((fixed, fixed_sign), (budget, budget_sign)) = (signed(&fixed), signed(&budget));
    let gaps: Vec<f64> = fixed.iter().zip(&budget).map(|(f, b)| f - b).collect();
    let (gap, _, se_gap) = mean_sd_se(&gaps);
    let (difference, _, se_difference) = mean_sd_se(&budget);
    let (fixed_difference, _, fixed_se_difference) = mean_sd_se(&fixed);
    Comparison {
        difference: budget_sign * difference,
        se_difference,
        fixed_difference: fixed_sign * fixed_difference,
        fixed_se_difference,
        gap,
        se_gap,
        nearer_beyond_2_se: gap > 2.0 * se_gap,
    }
}

/// Each budget point that lies within the fixed-radius curve's range of speed-ups on `axis`, or
/// beyond its fastest end, against that curve at its speed-up (figure 10's axes: the nearer
/// zero the change, the better), on the count and by obstacle; beyond the fastest radius,
/// against the fastest radius, which is slower. Budgets slower than every radius are left out.
pub(super) fn against_fixed(rows: &[Row], fixed: &[&Point], budget: &[&Point], axis: Axis) -> Vec<Against> {
    let mut curve: Vec<&Point> = fixed.to_vec();
    curve.sort_by(|a, b| axis.of(a).total_cmp(&axis.of(b)));
    let Some(&fastest) = curve.last() else {
        return Vec::new();
    };
    budget
        .iter()
        .filter_map(|b| {
            let speedup = axis.of(b);
            let (lo, hi, w, beyond) = match curve
                .windows(2)
                .position(|w| axis.of(w[0]) <= speedup && speedup <= axis.of(w[1]))
            {
                Some(i) => {
                    let (lo, hi) = (curve[i], curve[i + 1]);
                    let w = (speedup / axis.of(lo)).ln() / (axis.of(hi) / axis.of(lo)).ln().max(1e-12);
                    (lo, hi, w, false)
                }
                None if speedup > axis.of(fastest) => (fastest, fastest, 0.0, true),
                None => return None,
            };
            let on = |measure| compare(rows, b.of, (lo.of, hi.of, w), measure);
            Some(Against {
                budget_ms: b.setting,
                least_benefit_per_ms: b.least_benefit_per_ms,
                label: b.of.label(),
                speedup,
                count: on(Measure::Count),
                by_obstacle: on(Measure::ByObstacle),
                beyond_fastest_radius: beyond,
            })
        })
        .collect()
}
