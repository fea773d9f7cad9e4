//! `approx` 0.5 comparisons for the value types: field by field, with the tolerance
//! applied to every float.

use approx::{AbsDiffEq, RelativeEq, UlpsEq};

use crate::{Aabb, Interval, PlaneHit, Ray};

macro_rules! impl_approx {
    ($ty:ty { $($field:ident),+ }) => {
        impl AbsDiffEq for $ty {
            type Epsilon = f64;
            fn default_epsilon() -> f64 {
                f64::default_epsilon()
            }
            fn abs_diff_eq(&self, other: &Self, epsilon: f64) -> bool {
                $(AbsDiffEq::abs_diff_eq(&self.$field, &other.$field, epsilon))&&+
            }
        }

        impl RelativeEq for $ty {
            fn default_max_relative() -> f64 {
                f64::default_max_relative()
            }
            fn relative_eq(&self, other: &Self, epsilon: f64, max_relative: f64) -> bool {
                $(RelativeEq::relative_eq(&self.$field, &other.$field, epsilon, max_relative))&&+
            }
        }

        impl UlpsEq for $ty {
            fn default_max_ulps() -> u32 {
                f64::default_max_ulps()
            }
            fn ulps_eq(&self, other: &Self, epsilon: f64, max_ulps: u32) -> bool {
                $(UlpsEq::ulps_eq(&self.$field, &other.$field, epsilon, max_ulps))&&+
            }
        }
    };
}

impl_approx!(Ray {
    origin,
    direction,
    time
});
impl_approx!(Interval { min, max });
impl_approx!(Aabb { min, max });
impl_approx!(PlaneHit { t, alpha, beta });
