//! How it works: the map projections a dataset's metric CRS may use, forward (geodetic latitude
//! and longitude to easting and northing) and inverse, on the CRS's own ellipsoid, after IOGP's
//! Guidance Note 7-2 and Karney (2011):
//! - **Lambert Conformal Conic, two standard parallels** (EPSG method 9802; nc's State Plane):
//!   the cone's constant `n` and scale `F` from the two parallels' `m` and `t`, a point's radius
//!   `r = a F tⁿ` and angle `θ = n (λ − λ₀)`; the way back solves the isometric latitude for φ by
//!   fixed-point iteration.
//! - **Transverse Mercator** (EPSG 9807; UTM): Krüger's series in the third flattening `n` to n⁶,
//!   as Karney gives them (the conformal latitude via `τ′`, then the series in `ξ′ + iη′`); the way
//!   back inverts the series and solves `τ′ → τ` by Newton's method. Within a UTM zone it is exact
//!   to well under a millimetre, as PROJ's default `tmerc` (the same series) is.
//! - **Azimuthal Equidistant** (EPSG 1125 oblique; the builder's local frame of a geographic DEM):
//!   a point's distance and azimuth from the centre along the geodesic (`geodesic`), as PROJ's
//!   ellipsoidal `aeqd` takes them.
//!
//! Angles are radians inside and degrees in the stored parameters.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

use serde::{Deserialize, Serialize};

use super::ellipsoid::Ellipsoid;
use super::geodesic;

/// A map projection and its parameters (angles in degrees, lengths in metres).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "snake_case")]
pub enum Projection {
    /// Lambert Conformal Conic with two standard parallels (EPSG:9802).
    LambertConformalConic2Sp {
        /// Latitude of the false origin.
        lat_origin_deg: f64,
        /// Longitude of the false origin.
        lon_origin_deg: f64,
        /// First standard parallel.
        parallel_1_deg: f64,
        /// Second standard parallel.
        parallel_2_deg: f64,
        /// Easting at the false origin.
        false_easting_m: f64,
        /// Northing at the false origin.
        false_northing_m: f64,
    },
    /// Transverse Mercator (EPSG:9807).
    TransverseMercator {
        /// Latitude of the natural origin.
        lat_origin_deg: f64,
        /// Longitude of the natural origin (the central meridian).
        lon_origin_deg: f64,
        /// Scale factor on the central meridian.
        scale: f64,
        /// Easting at the natural origin.
        false_easting_m: f64,
        /// Northing at the natural origin.
        false_northing_m: f64,
    },
    /// Azimuthal Equidistant, on the ellipsoid's geodesics.
    AzimuthalEquidistant {
        /// Latitude of the centre.
        lat_origin_deg: f64,
        /// Longitude of the centre.
        lon_origin_deg: f64,
        /// Easting at the centre.
        false_easting_m: f64,
        /// Northing at the centre.
        false_northing_m: f64,
    },
}

/// `angle` brought into (−π, π].
fn wrap(angle: f64) -> f64 {
    let a = (angle + PI).rem_euclid(TAU) - PI;
    if a == -PI { PI } else { a }
}

impl Projection {
    /// Easting and northing, metres, of geodetic `lat`, `lon` (radians) on `ellipsoid`.
    pub fn forward(&self, ellipsoid: &Ellipsoid, lat: f64, lon: f64) -> [f64; 2] {
        match *self {
            Self::LambertConformalConic2Sp { lon_origin_deg, false_easting_m, false_northing_m, .. } => {
                let cone = Cone::new(self, ellipsoid);
                let r = cone.radius(lat);
                let theta = cone.n * wrap(lon - lon_origin_deg.to_radians());
                [false_easting_m + r * theta.sin(), false_northing_m + cone.r_origin - r * theta.cos()]
            }
            Self::TransverseMercator { lon_origin_deg, scale, false_easting_m, false_northing_m, .. } => {
                let tm = Kruger::new(self, ellipsoid);
                let (xi, eta) = tm.forward(lat, wrap(lon - lon_origin_deg.to_radians()));
                [
                    false_easting_m + scale * tm.a_rect * eta,
                    false_northing_m + scale * tm.a_rect * (xi - tm.xi_origin),
                ]
            }
            Self::AzimuthalEquidistant {
                lat_origin_deg,
                lon_origin_deg,
                false_easting_m,
                false_northing_m,
            } => {
                let (lat0, lon0) = (lat_origin_deg.to_radians(), lon_origin_deg.to_radians());
                // Nearly antipodal to the centre the geodesic is not found: no position.
                let (s, az) = geodesic::inverse(ellipsoid, lat0, lon0, lat, lon).unwrap_or((f64::NAN, 0.0));
                [false_easting_m + s * az.sin(), false_northing_m + s * az.cos()]
            }
        }
    }

    /// Geodetic latitude and longitude (radians) of easting `x_m`, northing `y_m` on `ellipsoid`.
    pub fn inverse(&self, ellipsoid: &Ellipsoid, x_m: f64, y_m: f64) -> (f64, f64) {
        match *self {
            Self::LambertConformalConic2Sp { lon_origin_deg, false_easting_m, false_northing_m, .. } => {
                let cone = Cone::new(self, ellipsoid);
                let (dx, dy) = (x_m - false_easting_m, cone.r_origin - (y_m - false_northing_m));
                let sign = cone.n.signum();
                let r = sign * dx.hypot(dy);
                let theta = (sign * dx).atan2(sign * dy);
                let t = (r / (ellipsoid.a_m * cone.f)).powf(1.0 / cone.n);
                (latitude_of_t(ellipsoid, t), wrap(theta / cone.n + lon_origin_deg.to_radians()))
            }
            Self::TransverseMercator { lon_origin_deg, scale, false_easting_m, false_northing_m, .. } => {
                let tm = Kruger::new(self, ellipsoid);
                let xi = (y_m - false_northing_m) / (scale * tm.a_rect) + tm.xi_origin;
                let eta = (x_m - false_easting_m) / (scale * tm.a_rect);
                let (lat, dlon) = tm.inverse(xi, eta);
                (lat, wrap(dlon + lon_origin_deg.to_radians()))
            }
            Self::AzimuthalEquidistant {
                lat_origin_deg,
                lon_origin_deg,
                false_easting_m,
                false_northing_m,
            } => {
                let (lat0, lon0) = (lat_origin_deg.to_radians(), lon_origin_deg.to_radians());
                let (dx, dy) = (x_m - false_easting_m, y_m - false_northing_m);
                let (lat, lon) = geodesic::direct(ellipsoid, lat0, lon0, dx.atan2(dy), dx.hypot(dy));
                (lat, wrap(lon))
            }
        }
    }
}

/// GN7-2's `m = cos φ / √(1 − e² sin² φ)`.
fn m_of(ellipsoid: &Ellipsoid, lat: f64) -> f64 {
    lat.cos() / (1.0 - ellipsoid.e2() * lat.sin().powi(2)).sqrt()
}

/// GN7-2's `t = tan(π/4 − φ/2) / ((1 − e sin φ) / (1 + e sin φ))^(e/2)`.
fn t_of(ellipsoid: &Ellipsoid, lat: f64) -> f64 {
    let (e, s) = (ellipsoid.e(), lat.sin());
    (FRAC_PI_4 - 0.5 * lat).tan() / ((1.0 - e * s) / (1.0 + e * s)).powf(0.5 * e)
}

/// The latitude whose `t` is `t`: φ = π/2 − 2 atan(t ((1 − e sin φ) / (1 + e sin φ))^(e/2)),
/// iterated from the sphere's.
fn latitude_of_t(ellipsoid: &Ellipsoid, t: f64) -> f64 {
    let e = ellipsoid.e();
    let mut lat = FRAC_PI_2 - 2.0 * t.atan();
    for _ in 0..20 {
        let s = lat.sin();
        let next = FRAC_PI_2 - 2.0 * (t * ((1.0 - e * s) / (1.0 + e * s)).powf(0.5 * e)).atan();
        if (next - lat).abs() < 1e-15 {
            return next;
        }
        lat = next;
    }
    lat
}

/// The Lambert cone of a projection.
struct Cone {
    n: f64,
    f: f64,
    /// `a F t(φ_origin)ⁿ`.
    r_origin: f64,
    a_m: f64,
    e: Ellipsoid,
}

impl Cone {
    fn new(projection: &Projection, ellipsoid: &Ellipsoid) -> Self {
        let Projection::LambertConformalConic2Sp { lat_origin_deg, parallel_1_deg, parallel_2_deg, .. } =
            *projection
        else {
            unreachable!("a cone of a conic projection only")
        };
        let (p1, p2) = (parallel_1_deg.to_radians(), parallel_2_deg.to_radians());
        let (m1, m2) = (m_of(ellipsoid, p1), m_of(ellipsoid, p2));
        let (t1, t2) = (t_of(ellipsoid, p1), t_of(ellipsoid, p2));
        // One standard parallel twice: the tangent cone.
        let n = if (p1 - p2).abs() > 1e-12 { (m1.ln() - m2.ln()) / (t1.ln() - t2.ln()) } else { p1.sin() };
        let f = m1 / (n * t1.powf(n));
        let r_origin = ellipsoid.a_m * f * t_of(ellipsoid, lat_origin_deg.to_radians()).powf(n);
        Self { n, f, r_origin, a_m: ellipsoid.a_m, e: *ellipsoid }
    }

    fn radius(&self, lat: f64) -> f64 {
        if (lat.abs() - FRAC_PI_2).abs() < 1e-15 && lat.signum() == self.n.signum() {
            return 0.0;
        }
        self.a_m * self.f * t_of(&self.e, lat).powf(self.n)
    }
}

/// Krüger's series of a Transverse Mercator projection's ellipsoid.
struct Kruger {
    e: f64,
    e2: f64,
    /// The rectifying radius `A`: a meridian's length is 2πA.
    a_rect: f64,
    alpha: [f64; 6],
    beta: [f64; 6],
    /// `ξ` of the natural origin (on the central meridian).
    xi_origin: f64,
}

impl Kruger {
    fn new(projection: &Projection, ellipsoid: &Ellipsoid) -> Self {
        let Projection::TransverseMercator { lat_origin_deg, .. } = *projection else {
            unreachable!("Krüger's series of a transverse Mercator only")
        };
        let f = ellipsoid.f();
        let n = f / (2.0 - f);
        let [n2, n3, n4, n5, n6] = [n * n, n.powi(3), n.powi(4), n.powi(5), n.powi(6)];
        let a_rect = ellipsoid.a_m / (1.0 + n) * (1.0 + n2 / 4.0 + n4 / 64.0 + n6 / 256.0);
        let alpha = [
            n / 2.0 - 2.0 * n2 / 3.0 + 5.0 * n3 / 16.0 + 41.0 * n4 / 180.0 - 127.0 * n5 / 288.0
                + 7891.0 * n6 / 37800.0,
            13.0 * n2 / 48.0 - 3.0 * n3 / 5.0 + 557.0 * n4 / 1440.0 + 281.0 * n5 / 630.0
                - 1_983_433.0 * n6 / 1_935_360.0,
            61.0 * n3 / 240.0 - 103.0 * n4 / 140.0 + 15061.0 * n5 / 26880.0 + 167_603.0 * n6 / 181_440.0,
            49561.0 * n4 / 161_280.0 - 179.0 * n5 / 168.0 + 6_601_661.0 * n6 / 7_257_600.0,
            34729.0 * n5 / 80640.0 - 3_418_889.0 * n6 / 1_995_840.0,
            212_378_941.0 * n6 / 319_334_400.0,
        ];
        let beta = [
            n / 2.0 - 2.0 * n2 / 3.0 + 37.0 * n3 / 96.0 - n4 / 360.0 - 81.0 * n5 / 512.0
                + 96199.0 * n6 / 604_800.0,
            n2 / 48.0 + n3 / 15.0 - 437.0 * n4 / 1440.0 + 46.0 * n5 / 105.0 - 1_118_711.0 * n6 / 3_870_720.0,
            17.0 * n3 / 480.0 - 37.0 * n4 / 840.0 - 209.0 * n5 / 4480.0 + 5569.0 * n6 / 90720.0,
            4397.0 * n4 / 161_280.0 - 11.0 * n5 / 504.0 - 830_251.0 * n6 / 7_257_600.0,
            4583.0 * n5 / 161_280.0 - 108_847.0 * n6 / 3_991_680.0,
            20_648_693.0 * n6 / 638_668_800.0,
        ];
        let mut k = Self { e: ellipsoid.e(), e2: ellipsoid.e2(), a_rect, alpha, beta, xi_origin: 0.0 };
        k.xi_origin = k.forward(lat_origin_deg.to_radians(), 0.0).0;
        k
    }

    /// `τ′`, the tangent of the conformal latitude, of `τ = tan φ`.
    fn tau_prime(&self, tau: f64) -> f64 {
        let sigma = (self.e * (self.e * tau / tau.hypot(1.0)).atanh()).sinh();
        tau * sigma.hypot(1.0) - sigma * tau.hypot(1.0)
    }

    /// (ξ, η) of latitude `lat` and longitude `dlon` from the central meridian.
    fn forward(&self, lat: f64, dlon: f64) -> (f64, f64) {
        let (sin_lat, cos_lat) = lat.sin_cos();
        let (xi_p, eta_p) = if cos_lat <= 1e-300 {
            (FRAC_PI_2.copysign(sin_lat), 0.0)
        } else {
            let tau_p = self.tau_prime(sin_lat / cos_lat);
            (tau_p.atan2(dlon.cos()), (dlon.sin() / tau_p.hypot(dlon.cos())).asinh())
        };
        let (mut xi, mut eta) = (xi_p, eta_p);
        for (j, a) in self.alpha.iter().enumerate() {
            let k = 2.0 * (j + 1) as f64;
            xi += a * (k * xi_p).sin() * (k * eta_p).cosh();
            eta += a * (k * xi_p).cos() * (k * eta_p).sinh();
        }
        (xi, eta)
    }

    /// Latitude and longitude from the central meridian of (ξ, η).
    fn inverse(&self, xi: f64, eta: f64) -> (f64, f64) {
        let (mut xi_p, mut eta_p) = (xi, eta);
        for (j, b) in self.beta.iter().enumerate() {
            let k = 2.0 * (j + 1) as f64;
            xi_p -= b * (k * xi).sin() * (k * eta).cosh();
            eta_p -= b * (k * xi).cos() * (k * eta).sinh();
        }
        let tau_p = xi_p.sin() / eta_p.sinh().hypot(xi_p.cos());
        let dlon = eta_p.sinh().atan2(xi_p.cos());
        // τ from τ′ by Newton's method (Karney 2011, eqs. 19–21).
        let mut tau = tau_p;
        for _ in 0..10 {
            let tp = self.tau_prime(tau);
            let step = (tau_p - tp) / tp.hypot(1.0) * (1.0 + (1.0 - self.e2) * tau * tau)
                / ((1.0 - self.e2) * tau.hypot(1.0));
            tau += step;
            if step.abs() <= 1e-15 * tau.abs().max(1.0) {
                break;
            }
        }
        (tau.atan(), dlon)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dms(d: f64, m: f64, s: f64) -> f64 {
        (d.abs() + m / 60.0 + s / 3600.0).copysign(d).to_radians()
    }

    /// US survey foot, metres.
    const FT_US: f64 = 1200.0 / 3937.0;

    #[test]
    fn lambert_two_parallels_matches_guidance_note_7_2() {
        // GN7-2 §3.1.1.1: NAD27 / Texas South Central on Clarke 1866.
        let clarke = Ellipsoid { a_m: 6_378_206.400, inv_f: 294.978_698_2 };
        let p = Projection::LambertConformalConic2Sp {
            lat_origin_deg: 27.0 + 50.0 / 60.0,
            lon_origin_deg: -99.0,
            parallel_1_deg: 28.0 + 23.0 / 60.0,
            parallel_2_deg: 30.0 + 17.0 / 60.0,
            false_easting_m: 2_000_000.0 * FT_US,
            false_northing_m: 0.0,
        };
        let (lat, lon) = (dms(28.0, 30.0, 0.0), dms(-96.0, 0.0, 0.0));
        let [x, y] = p.forward(&clarke, lat, lon);
        assert!((x / FT_US - 2_963_503.91).abs() < 0.01 && (y / FT_US - 254_759.80).abs() < 0.01, "{x} {y}");
        let (lat2, lon2) = p.inverse(&clarke, x, y);
        assert!((lat2 - lat).abs() < 1e-13 && (lon2 - lon).abs() < 1e-13, "{lat2} {lon2}");
    }

    #[test]
    fn transverse_mercator_matches_guidance_note_7_2() {
        // GN7-2 §3.5.3.1: OSGB 1936 / British National Grid on Airy 1830.
        let airy = Ellipsoid { a_m: 6_377_563.396, inv_f: 299.324_964_6 };
        let p = Projection::TransverseMercator {
            lat_origin_deg: 49.0,
            lon_origin_deg: -2.0,
            scale: 0.999_601_271_7,
            false_easting_m: 400_000.0,
            false_northing_m: -100_000.0,
        };
        let (lat, lon) = (dms(50.0, 30.0, 0.0), dms(0.0, 30.0, 0.0));
        let [x, y] = p.forward(&airy, lat, lon);
        assert!((x - 577_274.99).abs() < 0.01 && (y - 69_740.49).abs() < 0.01, "{x} {y}");
        let (lat2, lon2) = p.inverse(&airy, x, y);
        assert!((lat2 - lat).abs() < 1e-13 && (lon2 - lon).abs() < 1e-13, "{lat2} {lon2}");
    }

    #[test]
    fn azimuthal_equidistant_keeps_distances_from_its_centre() {
        let p = Projection::AzimuthalEquidistant {
            lat_origin_deg: 25.0,
            lon_origin_deg: 45.0,
            false_easting_m: 0.0,
            false_northing_m: 0.0,
        };
        let e = Ellipsoid::WGS84;
        // Due north along the meridian: y is the meridian arc from 25° N to 26° N, the integral of
        // the meridian's radius of curvature a (1 − e²) / (1 − e² sin² φ)^1.5 (Simpson's rule).
        let radius = |lat: f64| e.a_m * (1.0 - e.e2()) / (1.0 - e.e2() * lat.sin().powi(2)).powf(1.5);
        let (lo, hi, steps) = (25f64.to_radians(), 26f64.to_radians(), 100);
        let h = (hi - lo) / f64::from(steps);
        let arc = (0..=steps)
            .map(|k| {
                let w = if k == 0 || k == steps {
                    1.0
                } else if k % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                w * radius(lo + f64::from(k) * h)
            })
            .sum::<f64>()
            * h
            / 3.0;
        let [x, y] = p.forward(&e, hi, 45f64.to_radians());
        assert!(x.abs() < 1e-6 && (y - arc).abs() < 1e-4, "{x} {y} against {arc}");
        for (x, y) in [(0.0, 0.0), (1.0e3, -2.0e3), (-4.0e6, 3.0e6), (5.0e6, 1.0e5)] {
            let (lat, lon) = p.inverse(&e, x, y);
            let [x2, y2] = p.forward(&e, lat, lon);
            assert!((x2 - x).abs() < 1e-4 && (y2 - y).abs() < 1e-4, "{x} {y}: {x2} {y2}");
        }
    }

    #[test]
    fn both_ways_agree_over_a_zone_and_beyond() {
        let utm12 = Projection::TransverseMercator {
            lat_origin_deg: 0.0,
            lon_origin_deg: -111.0,
            scale: 0.9996,
            false_easting_m: 500_000.0,
            false_northing_m: 0.0,
        };
        let e = Ellipsoid::GRS80;
        for lat_deg in [-80.0, -30.0, 0.0, 37.2, 60.0, 84.0] {
            for dlon_deg in [-9.0, -3.0, 0.0, 0.001, 3.0, 9.0] {
                let (lat, lon) = (f64::to_radians(lat_deg), f64::to_radians(-111.0 + dlon_deg));
                let [x, y] = utm12.forward(&e, lat, lon);
                let (lat2, lon2) = utm12.inverse(&e, x, y);
                // 1e-12 rad is 6 µm on the ground.
                assert!((lat2 - lat).abs() < 1e-12 && (lon2 - lon).abs() < 1e-12, "{lat_deg} {dlon_deg}");
            }
        }
    }
}
