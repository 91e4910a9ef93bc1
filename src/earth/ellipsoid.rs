//! How it works: an ellipsoid of revolution (semi-major axis `a`, flattening `f`), and the map
//! between geodetic coordinates on it (latitude, longitude, height along the normal) and
//! Earth-centred, Earth-fixed Cartesian coordinates (the x axis through the prime meridian on the
//! equator, z through the north pole): `N = a / √(1 − e² sin² φ)`, `x = (N + h) cos φ cos λ`,
//! `y = (N + h) cos φ sin λ`, `z = (N (1 − e²) + h) sin φ`. The way back iterates Bowring's
//! parametric latitude to convergence (a few steps to well under a micrometre anywhere outside
//! the Earth's core).

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// An ellipsoid of revolution.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ellipsoid {
    /// Semi-major axis, metres.
    pub a_m: f64,
    /// Inverse flattening, 1 / f (0 for a sphere).
    pub inv_f: f64,
}

impl Ellipsoid {
    /// WGS 84 (EPSG:7030).
    pub const WGS84: Self = Self { a_m: 6_378_137.0, inv_f: 298.257_223_563 };
    /// GRS 1980 (EPSG:7019), NAD83's.
    pub const GRS80: Self = Self { a_m: 6_378_137.0, inv_f: 298.257_222_101 };

    /// Flattening.
    pub fn f(&self) -> f64 {
        if self.inv_f == 0.0 { 0.0 } else { 1.0 / self.inv_f }
    }

    /// First eccentricity squared, f (2 − f).
    pub fn e2(&self) -> f64 {
        let f = self.f();
        f * (2.0 - f)
    }

    /// First eccentricity.
    pub fn e(&self) -> f64 {
        self.e2().sqrt()
    }

    /// Semi-minor axis, metres.
    pub fn b_m(&self) -> f64 {
        self.a_m * (1.0 - self.f())
    }

    /// The Earth-centred position of latitude `lat` and longitude `lon` (radians) at `height_m`
    /// along the normal.
    pub fn ecef_m(&self, lat: f64, lon: f64, height_m: f64) -> DVec3 {
        let e2 = self.e2();
        let (sin_lat, cos_lat) = lat.sin_cos();
        let n = self.a_m / (1.0 - e2 * sin_lat * sin_lat).sqrt();
        let (sin_lon, cos_lon) = lon.sin_cos();
        DVec3::new(
            (n + height_m) * cos_lat * cos_lon,
            (n + height_m) * cos_lat * sin_lon,
            (n * (1.0 - e2) + height_m) * sin_lat,
        )
    }

    /// The geodetic latitude, longitude (radians) and height (metres) of Earth-centred `p`.
    pub fn geodetic(&self, p: DVec3) -> (f64, f64, f64) {
        let (a, b, e2) = (self.a_m, self.b_m(), self.e2());
        let ep2 = e2 / (1.0 - e2);
        let lon = p.y.atan2(p.x);
        let r = p.x.hypot(p.y);
        // Bowring's parametric latitude, iterated: each step brings it closer by a factor of
        // about e² sin 2φ.
        let mut beta = (p.z * a).atan2(r * b);
        let mut lat = 0.0;
        for _ in 0..8 {
            let (sin_b, cos_b) = beta.sin_cos();
            lat = (p.z + ep2 * b * sin_b.powi(3)).atan2(r - e2 * a * cos_b.powi(3));
            let next = ((1.0 - self.f()) * lat.sin()).atan2(lat.cos());
            if (next - beta).abs() < 1e-15 {
                break;
            }
            beta = next;
        }
        let (sin_lat, cos_lat) = lat.sin_cos();
        let n = a / (1.0 - e2 * sin_lat * sin_lat).sqrt();
        // The better conditioned of the two heights: by the radius away from the poles, by z near
        // them.
        let height_m = if cos_lat.abs() > 0.5 { r / cos_lat - n } else { p.z / sin_lat - n * (1.0 - e2) };
        (lat, lon, height_m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_points() {
        let e = Ellipsoid::WGS84;
        let equator = e.ecef_m(0.0, 0.0, 0.0);
        assert!((equator - DVec3::new(6_378_137.0, 0.0, 0.0)).length() < 1e-9);
        let pole = e.ecef_m(90f64.to_radians(), 0.0, 0.0);
        assert!((pole.z - 6_356_752.314_245).abs() < 1e-6 && pole.x.abs() < 1e-6, "{pole}");
        // GRS 80 and WGS 84 differ by 0.1 mm in the polar radius.
        let b = Ellipsoid::GRS80.b_m();
        assert!((b - 6_356_752.314_140).abs() < 1e-6, "{b}");
    }

    #[test]
    fn there_and_back() {
        let e = Ellipsoid::WGS84;
        for lat_deg in [-90.0, -89.999, -60.0, -1e-9, 0.0, 33.75, 45.0, 89.9999, 90.0] {
            for lon_deg in [-180.0, -79.0, 0.0, 45.0, 179.9999] {
                for h in [-430.0, 0.0, 8848.0, 4.0e5, 4.0e7] {
                    let (lat, lon) = (f64::to_radians(lat_deg), f64::to_radians(lon_deg));
                    let (lat2, lon2, h2) = e.geodetic(e.ecef_m(lat, lon, h));
                    assert!((lat2 - lat).abs() < 1e-12, "{lat_deg} {lon_deg} {h}: {lat2}");
                    if lat_deg.abs() < 90.0 {
                        let dlon = (lon2 - lon + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                            - std::f64::consts::PI;
                        assert!(dlon.abs() < 1e-12, "{lat_deg} {lon_deg} {h}: {lon2}");
                    }
                    assert!((h2 - h).abs() < 1e-6, "{lat_deg} {lon_deg} {h}: {h2}");
                }
            }
        }
    }
}
