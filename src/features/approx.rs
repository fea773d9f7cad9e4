//! `approx` 0.5 comparisons for the value types: field by field, with the tolerance
//! applied to every float (and a ray's mask compared exactly).

use approx::{AbsDiffEq, RelativeEq, UlpsEq};

use crate::{Aabb, Interval, PlaneHit, Ray};

macro_rules! impl_approx {
    ($ty:ty { $($field:ident),+ }) => {
        impl_approx!($ty { $($field),+ } exactly {});
    };
    ($ty:ty { $($field:ident),+ } exactly { $($exact:ident),* }) => {
        impl AbsDiffEq for $ty {
            type Epsilon = f64;
            fn default_epsilon() -> f64 {
                f64::default_epsilon()
            }
            fn abs_diff_eq(&self, other: &Self, epsilon: f64) -> bool {
                $(AbsDiffEq::abs_diff_eq(&self.$field, &other.$field, epsilon))&&+
                    $(&& self.$exact == other.$exact)*
            }
        }

        impl RelativeEq for $ty {
            fn default_max_relative() -> f64 {
                f64::default_max_relative()
            }
            fn relative_eq(&self, other: &Self, epsilon: f64, max_relative: f64) -> bool {
                $(RelativeEq::relative_eq(&self.$field, &other.$field, epsilon, max_relative))&&+
                    $(&& self.$exact == other.$exact)*
            }
        }

        impl UlpsEq for $ty {
            fn default_max_ulps() -> u32 {
                f64::default_max_ulps()
            }
            fn ulps_eq(&self, other: &Self, epsilon: f64, max_ulps: u32) -> bool {
                $(UlpsEq::ulps_eq(&self.$field, &other.$field, epsilon, max_ulps))&&+
                    $(&& self.$exact == other.$exact)*
            }
        }
    };
}

impl_approx!(Ray { origin, direction, time } exactly { mask });
impl_approx!(Interval { min, max });
impl_approx!(Aabb { min, max });
impl_approx!(PlaneHit { t, alpha, beta });
