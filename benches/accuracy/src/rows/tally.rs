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
    /// A hit whose point lies farther from the true shape than the contract's bound,
    /// `2^-43 M / s^2` (see `hitkit_render::distance::planar_bound`).
    FalseHit,
    /// A spawned ray hits the surface it left.
    SelfHit,
    /// A ray misses a surface it meets (or a box test rejects a box whose quad is hit).
    Lost,
    /// A hit whose `t`, point, normal or `(alpha, beta)` is NaN.
    Nan,
}

impl Failure {
    /// Every kind, in the table's order.
    pub const ALL: [Failure; 5] = [
        Failure::Crack,
        Failure::FalseHit,
        Failure::SelfHit,
        Failure::Lost,
        Failure::Nan,
    ];

    /// The kind's name in the printed text.
    pub fn label(self) -> &'static str {
        match self {
            Failure::Crack => "cracks",
            Failure::FalseHit => "false hits",
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
    /// `(kind, "part of a workload at placement")`: how many.
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

    /// The failures of `kind` by part of a workload, most first.
    pub fn parts(&self, kind: Failure) -> Vec<Part> {
        let mut parts: BTreeMap<&str, Part> = BTreeMap::new();
        for ((k, place), &n) in &self.places {
            if *k != kind {
                continue;
            }
            let (name, placement) = place.rsplit_once(" at ").unwrap_or((place.as_str(), ""));
            let part = parts.entry(name).or_insert_with(|| Part {
                name: name.to_string(),
                count: 0,
                worst: (String::new(), 0),
            });
            part.count += n;
            if n > part.worst.1 {
                part.worst = (placement.to_string(), n);
            }
        }
        let mut parts: Vec<Part> = parts.into_values().collect();
        parts.sort_by(|a, b| b.count.cmp(&a.count).then_with(|| a.name.cmp(&b.name)));
        parts
    }
}

/// The failures of one kind in one part of a workload (the place's name before its last
/// " at "): how many, and the placement where most of them are.
pub struct Part {
    pub name: String,
    pub count: u64,
    pub worst: (String, u64),
}

/// One row of the table.
pub struct Row {
    pub choice: String,
    pub fixes: String,
    pub measured: Measured,
}

/// What one choice was measured to do.
pub struct Measured {
    pub tally: Tally,
    pub ns_per_ray: f64,
    /// For the quad-test rows, the time per ray on rays through the faces' insides (the
    /// typical ray of a render), beside `ns_per_ray` on rays at edges.
    pub ns_per_inside_ray: Option<f64>,
}

impl Measured {
    /// Counts and a time.
    pub fn new(tally: Tally, ns_per_ray: f64) -> Self {
        Self {
            tally,
            ns_per_ray,
            ns_per_inside_ray: None,
        }
    }
}

/// A row from its texts and what was measured.
pub fn row(choice: impl Into<String>, fixes: impl Into<String>, measured: Measured) -> Row {
    Row {
        choice: choice.into(),
        fixes: fixes.into(),
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
