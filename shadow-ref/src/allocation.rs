//! The adaptive reference's allocation of samples to pixels (`ref-adaptive-*`): the
//! MSE-optimal progressive-set size per pixel from its probe variance, for an image RMSE.

/// The progressive-set size of every pixel with variance `c_i` (0 where nothing is sampled):
/// `n_i = K c_i^(2/5)` within `[B, largest]`, `K` such that the modelled image MSE
/// `sum c_i (n_i / B)^-3/2 / pixels` is `target^2`, each count rounded to the nearest of
/// `schedule` in log scale.
pub(crate) fn allocate(vars: &[f64], pixels: usize, target: f64, schedule: &[u32]) -> Vec<u32> {
    let b = f64::from(schedule[0]);
    let largest = f64::from(*schedule.last().expect("the schedule is not empty"));
    // (c, c^(2/5)) of the pixels that plan at all, computed once: the bisection below
    // evaluates the modelled error some sixty times.
    let planned: Vec<(f64, f64)> = vars
        .iter()
        .filter(|&&c| c > 0.0)
        .map(|&c| (c, c.powf(0.4)))
        .collect();
    let mse = |k: f64| {
        planned
            .iter()
            .map(|&(c, a)| {
                let x = (k * a).clamp(b, largest) / b;
                c / (x * x.sqrt())
            })
            .sum::<f64>()
            / pixels.max(1) as f64
    };
    let goal = target * target;
    let (mut lo, mut hi) = (-60.0f64, 60.0f64);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if mse(mid.exp()) > goal {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let k = hi.exp();
    vars.iter()
        .map(|&c| {
            if !(c > 0.0) {
                return schedule[0];
            }
            let n = (k * c.powf(0.4)).clamp(b, largest).ln();
            *schedule
                .iter()
                .min_by(|a, z| {
                    (f64::from(**a).ln() - n)
                        .abs()
                        .total_cmp(&(f64::from(**z).ln() - n).abs())
                })
                .expect("the schedule is not empty")
        })
        .collect()
}
