//! What a row of the table records (failure counts by kind and by place, and a time) and
//! how the time is taken.

use std::collections::BTreeMap;
use std::hint::black_box;
use std::time::Instant;

/// The kinds of failure the table counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Failure {
    /// A ray aimed at a shared edge or corner hits none of the shapes sharing it.
    Crack,
    /// A spawned ray hits the surface it left.
    SelfHit,
    /// A ray misses a surface it meets (or a box test rejects a box whose quad is hit).
    Lost,
    /// A hit whose `t`, point, normal or `(alpha, beta)` is NaN.
    Nan,
}

impl Failure {
    /// Every kind, in the table's order.
    pub const ALL: [Failure; 4] = [
        Failure::Crack,
        Failure::SelfHit,
        Failure::Lost,
        Failure::Nan,
    ];

    /// The kind's name in the printed text.
    pub fn label(self) -> &'static str {
        match self {
            Failure::Crack => "cracks",
            Failure::SelfHit => "self-hits",
            Failure::Lost => "lost hits",
            Failure::Nan => "NaNs",
        }
    }
}

/// Failure counts of one choice: by kind, and by kind and where they happened.
#[derive(Clone, Debug, Default)]
pub struct Tally {
    counts: BTreeMap<Failure, u64>,
    /// `(kind, "workload, placement")`: how many.
    places: BTreeMap<(Failure, String), u64>,
}

impl Tally {
    /// Counts one failure of `kind` at `place` (a closure, so that the label is only built
    /// when something fails).
    pub fn add(&mut self, kind: Failure, place: impl FnOnce() -> String) {
        *self.counts.entry(kind).or_default() += 1;
        *self.places.entry((kind, place())).or_default() += 1;
    }

    /// Makes sure `kind` shows as counted (0) even if nothing failed.
    pub fn measured(&mut self, kind: Failure) {
        self.counts.entry(kind).or_default();
    }

    /// The failures of `kind`, or `None` if the choice was not measured for it.
    pub fn count(&self, kind: Failure) -> Option<u64> {
        self.counts.get(&kind).copied()
    }

    /// All failures counted.
    pub fn total(&self) -> u64 {
        self.counts.values().sum()
    }

    /// Where the failures of `kind` happened, most first, as "place: count".
    pub fn places(&self, kind: Failure) -> Vec<String> {
        let mut places: Vec<_> = self
            .places
            .iter()
            .filter(|((k, _), _)| *k == kind)
            .map(|((_, place), n)| (place, *n))
            .collect();
        places.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(b.0)));
        places
            .into_iter()
            .map(|(place, n)| format!("{place}: {n}"))
            .collect()
    }
}

/// One row of the table.
pub struct Row {
    pub choice: &'static str,
    pub fixes: &'static str,
    pub measured: Measured,
}

/// What one choice was measured to do.
pub struct Measured {
    pub tally: Tally,
    /// Rays at the edges of the boxes, and at the shared edge of the coplanar pairs, whose
    /// corners were rounded one by one, that hit no shape (not in the table: the geometry
    /// has gaps there), if the choice ran them.
    pub rounded_cracks: Option<(u64, u64)>,
    pub ns_per_ray: f64,
}

impl Measured {
    /// Counts and a time, with no rounded-corner boxes run.
    pub fn new(tally: Tally, ns_per_ray: f64) -> Self {
        Self {
            tally,
            rounded_cracks: None,
            ns_per_ray,
        }
    }
}

/// A row from its texts and what was measured.
pub fn row(choice: &'static str, fixes: &'static str, measured: Measured) -> Row {
    Row {
        choice,
        fixes,
        measured,
    }
}

/// The median, over `repetitions` runs of `run`, of its time per ray, in nanoseconds.
pub fn median_ns_per_ray(repetitions: usize, rays: usize, mut run: impl FnMut() -> u64) -> f64 {
    let mut times: Vec<f64> = (0..repetitions.max(1))
        .map(|_| {
            let start = Instant::now();
            black_box(run());
            start.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2] * 1e9 / rays.max(1) as f64
}

/// `1e12`, `1`, `1e-6`, `6e11`: a placement's numbers as the text prints them.
pub fn short(x: f64) -> String {
    if x == 0.0 || (1.0..10.0).contains(&x) {
        return format!("{x}");
    }
    let exponent = x.abs().log10().floor() as i32;
    let mantissa = x / 10f64.powi(exponent);
    if (mantissa - 1.0).abs() < 1e-9 {
        format!("1e{exponent}")
    } else {
        format!("{mantissa}e{exponent}")
    }
}
