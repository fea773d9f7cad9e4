//! The box-test rows: the book's slab test and `hitkit::Aabb::hit`, each on the book's kind
//! of box and on hitkit's, counting boxes lost whose square is hit.

use std::hint::black_box;

use hitkit::{Aabb, Hittable, Interval, Quad, Ray};

use crate::numbers::short;
use crate::rows::book::{self, BookBox, BookQuad, BookShape};
use crate::rows::quads::build_all;
use crate::rows::tally::{Failure, Measured, Row, Tally, median_ns_per_ray, row};
use crate::workloads::boxes::{BOX_OFFSETS, BoxRay, Boxes};

/// A box test and the boxes it runs on, as the boxes rows run them.
#[derive(Clone, Copy, Debug)]
enum BoxTest {
    /// The book's slab test on the book's box (0.0001 padding), over `[0.001, inf)`.
    Book,
    /// The book's slab test on the quad's hitkit box (padded relative to its size and
    /// position, and grown by the rounding of its corners).
    BookOnHitkitBox,
    /// `hitkit::Aabb::hit` on `Aabb::new(q, q + u + v)`: the square's own extent (padded
    /// only where flat), whose faces lie in the slab planes of the rays along the edges.
    HitkitOnTightBox,
    /// `hitkit::Aabb::hit` on the quad's hitkit box, over `[0, inf)`.
    Hitkit,
}

/// The boxes of one [`BoxTest`]: the book's or hitkit's, per square.
enum BoxSet {
    Book(Vec<BookBox>),
    Hitkit(Vec<Aabb>),
}

impl BoxSet {
    /// Whether the box of square `quad` passes `test` for `ray`.
    #[inline]
    fn hit(&self, quad: usize, ray: &Ray) -> bool {
        match self {
            BoxSet::Book(boxes) => boxes[quad].hit(ray, Interval::new(book::T_MIN, f64::INFINITY)),
            BoxSet::Hitkit(boxes) => boxes[quad].hit(ray, Interval::new(0.0, f64::INFINITY)),
        }
    }
}

/// What the boxes rows found beside their counts.
#[derive(Clone, Debug, Default)]
pub struct BoxNotes {
    /// Rays on which the book's slab test computed a NaN slab distance (book's box).
    pub book_nan_rays: u64,
    /// Rays built to meet their square that hitkit's own quad test rejected (not counted).
    pub leaf_rejected: u64,
    pub rays: usize,
}

/// The book's box of every square.
fn book_boxes(boxes: &Boxes) -> Vec<BookBox> {
    boxes
        .quads
        .iter()
        .map(|s| BookQuad::new(s.q, s.u, s.v, BookShape::Parallelogram).bounding_box())
        .collect()
}

/// The boxes `test` runs on, one per square (`leaves` are hitkit's quads of the squares).
fn box_set(test: BoxTest, boxes: &Boxes, leaves: &[Quad]) -> BoxSet {
    match test {
        BoxTest::Book => BoxSet::Book(book_boxes(boxes)),
        BoxTest::BookOnHitkitBox => BoxSet::Book(
            leaves
                .iter()
                .map(|q| BookBox::from_aabb(&q.bounding_box()))
                .collect(),
        ),
        BoxTest::HitkitOnTightBox => BoxSet::Hitkit(
            boxes
                .quads
                .iter()
                .map(|s| Aabb::new(s.q, s.q + s.u + s.v))
                .collect(),
        ),
        BoxTest::Hitkit => BoxSet::Hitkit(leaves.iter().map(|q| q.bounding_box()).collect()),
    }
}

/// One box-test row: lost boxes (the quad's test accepts, the box test rejects) and the
/// time per box test.
fn box_row(
    test: BoxTest,
    boxes: &Boxes,
    leaves: &[Quad],
    accepted: &[bool],
    repetitions: usize,
) -> Measured {
    let set = box_set(test, boxes, leaves);
    let mut tally = Tally::default();
    tally.measured(Failure::Lost);
    for (&BoxRay { quad, ray, kind }, &accepted) in boxes.rays.iter().zip(accepted) {
        if accepted && !set.hit(quad, &ray) {
            tally.add(Failure::Lost, || {
                format!("{} at {}", kind.label(), short(boxes.offsets[quad]))
            });
        }
    }
    let ns = median_ns_per_ray(repetitions, boxes.rays.len(), || {
        let mut hits = 0;
        for r in &boxes.rays {
            if black_box(&set).hit(r.quad, black_box(&r.ray)) {
                hits += 1;
            }
        }
        hits
    });
    Measured::new(tally, ns)
}

/// The three box-test rows and the notes on them.
pub fn box_rows(boxes: &Boxes, repetitions: usize) -> Result<(Vec<Row>, BoxNotes), String> {
    let leaves = build_all(&boxes.quads, |s| Quad::new(s.q, s.u, s.v), "square")?;
    let accepted: Vec<bool> = boxes
        .rays
        .iter()
        .map(|r| {
            leaves[r.quad]
                .hit(&r.ray, Interval::new(0.0, f64::INFINITY))
                .is_some()
        })
        .collect();
    let book_boxes = book_boxes(boxes);
    let notes = BoxNotes {
        book_nan_rays: boxes
            .rays
            .iter()
            .filter(|r| book_boxes[r.quad].computes_nan(&r.ray))
            .count() as u64,
        leaf_rejected: accepted.iter().filter(|&&a| !a).count() as u64,
        rays: boxes.rays.len(),
    };
    let farthest = short(BOX_OFFSETS[BOX_OFFSETS.len() - 1]);
    let tests = [
        (
            BoxTest::Book,
            format!(
                "box test: the book's slab test, {} padding",
                book::BOX_PADDING
            ),
            "nothing (the baseline)".to_string(),
        ),
        (
            BoxTest::BookOnHitkitBox,
            "box test: the book's slab test on hitkit's box".to_string(),
            format!(
                "hitkit's boxes alone: relative padding survives rounding at {farthest}, and \
                 growth by the corners' rounding takes box faces off these rays' slab planes"
            ),
        ),
        (
            BoxTest::HitkitOnTightBox,
            "box test: hitkit `Aabb::hit` on `Aabb::new(q, q + u + v)`".to_string(),
            "the slab test alone: a ray lying in a box face (0 * inf = NaN) hits; relative \
             padding of flat sides"
                .to_string(),
        ),
        (
            BoxTest::Hitkit,
            "box test: hitkit `Aabb::hit` on the quad's box".to_string(),
            "both: hitkit's default, a quad's `bounding_box()` tested by `Aabb::hit`".to_string(),
        ),
    ];
    let rows = tests
        .into_iter()
        .map(|(test, choice, fixes)| {
            row(
                choice,
                fixes,
                box_row(test, boxes, &leaves, &accepted, repetitions),
            )
        })
        .collect();
    Ok((rows, notes))
}
