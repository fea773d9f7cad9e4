//! The workloads: hard-case rays and the shapes they aim at, generated once from a fixed
//! seed and shared by every row, so that every row runs on exactly the same rays. Each
//! describes itself from the constants that build it.

pub mod boxes;
pub mod degenerate;
pub mod edges;
pub mod frame;
pub mod grazing;
pub mod inside;
pub mod spawn;

use boxes::Boxes;
use degenerate::Degenerate;
use edges::Edges;
use grazing::Grazing;
use spawn::Spawn;

/// All the workloads, generated once and shared by every choice.
pub struct Workloads {
    pub edges: Edges,
    pub grazing: Grazing,
    pub spawn: Spawn,
    pub degenerate: Degenerate,
    pub boxes: Boxes,
}

impl Workloads {
    /// Every workload; `size` scales the number of rays (1.0 for the full run).
    pub fn generate(size: f64) -> Self {
        Self {
            edges: Edges::generate(size),
            grazing: Grazing::generate(size),
            spawn: Spawn::generate(size),
            degenerate: Degenerate::generate(size),
            boxes: Boxes::generate(size),
        }
    }
}

impl Workloads {
    /// What the workloads are, one paragraph each, for the printed text.
    pub fn describe(&self) -> String {
        format!(
            "Workloads (seed {:#x}, deterministic; every row runs on exactly the same rays):\n\n\
             {}\n{}\n{}\n{}\n{}",
            frame::SEED,
            self.edges.describe(),
            self.grazing.describe(),
            self.spawn.describe(),
            self.degenerate.describe(),
            self.boxes.describe(),
        )
    }
}
