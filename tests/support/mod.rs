//! What several test files share: the rounding bound, a fixed random stream (the one the
//! benches use), the placements of the contract's shapes, a set of lights, and the check
//! that two renders agree on a mean.
#![allow(dead_code)]

#[allow(unused_imports)] // not every test file uses it
pub use hitkit_render::distance;
#[allow(unused_imports)]
pub use hitkit_render::workloads::{
    SplitMix, cube_corner, cube_faces, face_point, icosphere, instances,
};

/// Offsets that round every corner built from them (none is a power of two), 0 to ~1e12.
pub const OFFSETS: [f64; 5] = [0.0, 1234.567, 1.1e6 + 0.3, 3.3e9 + 0.7, 1.7e12 + 0.1];
/// Sizes from 1e-6 to 1e6 (not powers of two either).
pub const SIZES: [f64; 5] = [1.3e-6, 1.7e-3, 1.1, 1.9e3, 1.3e6];

/// Whether a shape of `size` at `offset` is representable with room to spare: its size is
/// at least 2^20 ulps of the offset, so that it is more than its own rounding.
pub fn meaningful(offset: f64, size: f64) -> bool {
    size >= offset * f64::EPSILON * 1048576.0
}

/// Every (offset, size) pair of `OFFSETS` and `SIZES` that is [`meaningful`].
pub fn placements() -> impl Iterator<Item = (f64, f64)> {
    OFFSETS
        .iter()
        .flat_map(|&offset| SIZES.iter().map(move |&size| (offset, size)))
        .filter(|&(offset, size)| meaningful(offset, size))
}

/// A rotation about a random axis by a random angle, as a user's `from_axis_angle` makes.
pub fn rotation(rng: &mut SplitMix) -> hitkit::glam::DMat3 {
    hitkit::glam::DMat3::from_axis_angle(rng.direction(), std::f64::consts::TAU * rng.next_f64())
}

/// `gamma(k) = k u / (1 - k u)`, `u` the unit roundoff: bounds `k` chained roundings.
pub fn gamma(k: u32) -> f64 {
    let nu = f64::from(k) * f64::EPSILON * 0.5;
    nu / (1.0 - nu)
}

/// Four lights of every kind, around the origin: a unit square 2 above it (sampled by solid
/// angle from nearby), a disk to one side, a triangle below and a sphere to the other side.
pub fn four_lights() -> Vec<Box<dyn hitkit::PdfHittable>> {
    use hitkit::glam::DVec3;
    use hitkit::{Disk, Quad, Sphere, Triangle};
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    vec![
        Box::new(Quad::new(DVec3::new(-1.0, 2.0, -1.0), x, z).unwrap()),
        Box::new(Quad::with_interior(DVec3::new(1.5, 1.0, 0.0), 0.5 * y, 0.5 * z, Disk).unwrap()),
        Box::new(Quad::with_interior(DVec3::new(0.0, -2.0, 1.0), x, z, Triangle).unwrap()),
        Box::new(Sphere::new(DVec3::new(-2.0, 0.0, 0.0), 0.5).unwrap()),
    ]
}

/// The closest hit of a list and its position, ties at equal `t` going to the earlier
/// object: what a `Bvh` must return.
pub fn brute_force<T: hitkit::Hittable>(
    objects: &[T],
    ray: &hitkit::Ray,
    ray_t: hitkit::Interval,
) -> Option<(usize, hitkit::HitRecord)> {
    let mut best: Option<(usize, hitkit::HitRecord)> = None;
    for (i, o) in objects.iter().enumerate() {
        if let Some(h) = o.hit(ray, ray_t)
            && best.is_none_or(|(_, b)| h.t < b.t)
        {
            best = Some((i, h));
        }
    }
    best
}

/// The closest hit of the loop over a mesh's faces that `keep` takes (by the face's
/// number), ties at equal `t` going to the face numbered first: what the mesh's tree (or a
/// filter turning away the others) must return.
pub fn loop_over_faces(
    mesh: &hitkit::TriangleMesh,
    ray: &hitkit::Ray,
    ray_t: hitkit::Interval,
    keep: impl Fn(u32) -> bool,
) -> Option<hitkit::HitRecord> {
    use hitkit::Hittable;
    let mut best: Option<hitkit::HitRecord> = None;
    for face in mesh.faces().filter(|f| keep(f.index())) {
        if let Some(h) = face.hit(ray, ray_t)
            && best.is_none_or(|b| h.t < b.t || (h.t == b.t && h.primitive < b.primitive))
        {
            best = Some(h);
        }
    }
    best
}

/// The mean of `values` and its standard error (from their sample variance).
pub fn mean_and_error(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Whether two estimates of one mean agree: within 4 standard errors of their difference
/// (`sqrt(se_a^2 + se_b^2)`, each from per-pixel sample variances), a false alarm once in
/// about 16,000 runs for normal errors (path contributions are heavy-tailed, which the
/// sample variance only partly captures). And the comparison must mean something: the
/// error small against the mean.
pub fn assert_same_mean((mean_a, se_a): (f64, f64), (mean_b, se_b): (f64, f64), what: &str) {
    let se = (se_a * se_a + se_b * se_b).sqrt();
    assert!(
        (mean_a - mean_b).abs() <= 4.0 * se,
        "{what}: {mean_a} +- {se_a} vs {mean_b} +- {se_b}"
    );
    assert!(
        se < 0.05 * mean_a,
        "{what}: standard error {se} too large for mean {mean_a}"
    );
}

/// Writes a PNG of `width` x `height` 8-bit RGBA texels, row by row from the top (for the
/// glTF tests' images).
pub fn write_png(path: &std::path::Path, width: u32, height: u32, texels: &[[u8; 4]]) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().unwrap();
    writer.write_image_data(texels.as_flattened()).unwrap();
}
