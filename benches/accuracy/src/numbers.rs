//! How the text prints numbers: `1e12`, `1e-6 to 1e6`, and the like.

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

/// `first to last` of a list of numbers, as the text prints them.
pub fn span(values: &[f64]) -> String {
    match values {
        [] => String::new(),
        [only] => short(*only),
        [first, .., last] => format!("{} to {}", short(*first), short(*last)),
    }
}

/// `10^lo to 10^hi`, as the text prints them.
pub fn decades((lo, hi): (f64, f64)) -> String {
    format!("{} to {}", short(10f64.powf(lo)), short(10f64.powf(hi)))
}
