//! How it works: geodesics on an ellipsoid by Vincenty's formulae (Survey Review, 1975), which the
//! azimuthal equidistant projection needs: the **direct** problem (from a point, an azimuth and a
//! distance, where the geodesic ends) iterates the arc length on the auxiliary sphere and always
//! converges; the **inverse** problem (the distance and azimuth between two points) iterates the
//! longitude on the auxiliary sphere and converges except for nearly antipodal points, where it
//! gives up after `MAX_STEPS` and says so. Both are good to well under a millimetre on the Earth
//! (Vincenty's own bound is 0.5 mm; PROJ's `aeqd` uses Karney's geodesics, which agree with them to
//! micrometres away from the antipode).

use super::ellipsoid::Ellipsoid;

/// Most iterations of either problem.
const MAX_STEPS: usize = 200;
/// Convergence of the iterated angle, radians (6 µm on the Earth).
const CONVERGED: f64 = 1e-12;

/// Vincenty's A and B of `u² = cos² α (a² − b²) / b²`.
fn series(u2: f64) -> (f64, f64) {
    let a = 1.0 + u2 / 16384.0 * (4096.0 + u2 * (-768.0 + u2 * (320.0 - 175.0 * u2)));
    let b = u2 / 1024.0 * (256.0 + u2 * (-128.0 + u2 * (74.0 - 47.0 * u2)));
    (a, b)
}

/// Δσ of an arc σ whose midpoint is at 2σₘ (`cos_2sm`).
fn delta_sigma(b: f64, sin_s: f64, cos_s: f64, cos_2sm: f64) -> f64 {
    let c2 = cos_2sm * cos_2sm;
    b * sin_s
        * (cos_2sm
            + b / 4.0
                * (cos_s * (-1.0 + 2.0 * c2)
                    - b / 6.0 * cos_2sm * (-3.0 + 4.0 * sin_s * sin_s) * (-3.0 + 4.0 * c2)))
}

/// Where the geodesic from `lat`, `lon` (radians) leaving at `azimuth` (radians clockwise from
/// north) ends after `distance_m`: its latitude and longitude.
pub fn direct(e: &Ellipsoid, lat: f64, lon: f64, azimuth: f64, distance_m: f64) -> (f64, f64) {
    let (a, f) = (e.a_m, e.f());
    let b_axis = e.b_m();
    let (sin_az, cos_az) = azimuth.sin_cos();
    let tan_u1 = (1.0 - f) * lat.tan();
    let cos_u1 = 1.0 / tan_u1.hypot(1.0);
    let sin_u1 = tan_u1 * cos_u1;
    let sigma1 = tan_u1.atan2(cos_az);
    let sin_alpha = cos_u1 * sin_az;
    let cos2_alpha = 1.0 - sin_alpha * sin_alpha;
    let u2 = cos2_alpha * (a * a - b_axis * b_axis) / (b_axis * b_axis);
    let (big_a, big_b) = series(u2);
    let mut sigma = distance_m / (b_axis * big_a);
    let mut cos_2sm = (2.0 * sigma1 + sigma).cos();
    for _ in 0..MAX_STEPS {
        cos_2sm = (2.0 * sigma1 + sigma).cos();
        let next = distance_m / (b_axis * big_a) + delta_sigma(big_b, sigma.sin(), sigma.cos(), cos_2sm);
        let done = (next - sigma).abs() < CONVERGED;
        sigma = next;
        if done {
            break;
        }
    }
    let (sin_s, cos_s) = sigma.sin_cos();
    let x = sin_u1 * sin_s - cos_u1 * cos_s * cos_az;
    let lat2 = (sin_u1 * cos_s + cos_u1 * sin_s * cos_az).atan2((1.0 - f) * sin_alpha.hypot(x));
    let lambda = (sin_s * sin_az).atan2(cos_u1 * cos_s - sin_u1 * sin_s * cos_az);
    let c = f / 16.0 * cos2_alpha * (4.0 + f * (4.0 - 3.0 * cos2_alpha));
    let l = lambda
        - (1.0 - c)
            * f
            * sin_alpha
            * (sigma + c * sin_s * (cos_2sm + c * cos_s * (-1.0 + 2.0 * cos_2sm * cos_2sm)));
    (lat2, lon + l)
}

/// The distance (metres) and the azimuth at the first point (radians clockwise from north) of the
/// geodesic from `lat1`, `lon1` to `lat2`, `lon2`; `None` where the iteration does not converge
/// (nearly antipodal points).
pub fn inverse(e: &Ellipsoid, lat1: f64, lon1: f64, lat2: f64, lon2: f64) -> Option<(f64, f64)> {
    let (a, f) = (e.a_m, e.f());
    let b_axis = e.b_m();
    let l = lon2 - lon1;
    let (u1, u2) = (((1.0 - f) * lat1.tan()).atan(), ((1.0 - f) * lat2.tan()).atan());
    let ((sin_u1, cos_u1), (sin_u2, cos_u2)) = (u1.sin_cos(), u2.sin_cos());
    let mut lambda = l;
    for _ in 0..MAX_STEPS {
        let (sin_l, cos_l) = lambda.sin_cos();
        let sin_s = (cos_u2 * sin_l).hypot(cos_u1 * sin_u2 - sin_u1 * cos_u2 * cos_l);
        if sin_s == 0.0 {
            return Some((0.0, 0.0));
        }
        let cos_s = sin_u1 * sin_u2 + cos_u1 * cos_u2 * cos_l;
        let sigma = sin_s.atan2(cos_s);
        let sin_alpha = cos_u1 * cos_u2 * sin_l / sin_s;
        let cos2_alpha = 1.0 - sin_alpha * sin_alpha;
        // On the equator cos² α is 0 and so is 2σₘ's cosine's use.
        let cos_2sm = if cos2_alpha != 0.0 { cos_s - 2.0 * sin_u1 * sin_u2 / cos2_alpha } else { 0.0 };
        let c = f / 16.0 * cos2_alpha * (4.0 + f * (4.0 - 3.0 * cos2_alpha));
        let next = l
            + (1.0 - c)
                * f
                * sin_alpha
                * (sigma + c * sin_s * (cos_2sm + c * cos_s * (-1.0 + 2.0 * cos_2sm * cos_2sm)));
        if (next - lambda).abs() < CONVERGED {
            let u_sq = cos2_alpha * (a * a - b_axis * b_axis) / (b_axis * b_axis);
            let (big_a, big_b) = series(u_sq);
            let distance = b_axis * big_a * (sigma - delta_sigma(big_b, sin_s, cos_s, cos_2sm));
            let (sin_n, cos_n) = next.sin_cos();
            let azimuth = (cos_u2 * sin_n).atan2(cos_u1 * sin_u2 - sin_u1 * cos_u2 * cos_n);
            return Some((distance, azimuth));
        }
        lambda = next;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dms(d: f64, m: f64, s: f64) -> f64 {
        (d.abs() + m / 60.0 + s / 3600.0).copysign(d).to_radians()
    }

    #[test]
    fn flinders_peak_to_buninyong() {
        // Geoscience Australia's worked example of Vincenty's formulae, on GRS 80: from Flinders
        // Peak (37°57′03.72030″ S, 144°25′29.52440″ E) to Buninyong (37°39′10.15610″ S,
        // 143°55′35.38390″ E), 54,972.271 m at 306°52′05.37″.
        let e = Ellipsoid::GRS80;
        let (lat1, lon1) = (dms(-37.0, 57.0, 3.72030), dms(144.0, 25.0, 29.52440));
        let (lat2, lon2) = (dms(-37.0, 39.0, 10.15610), dms(143.0, 55.0, 35.38390));
        let (s, az) = inverse(&e, lat1, lon1, lat2, lon2).unwrap();
        assert!((s - 54_972.271).abs() < 0.001, "{s}");
        assert!(
            (az.to_degrees().rem_euclid(360.0) - (306.0 + 52.0 / 60.0 + 5.37 / 3600.0)).abs() < 1e-5,
            "{az}"
        );
        let (lat, lon) = direct(&e, lat1, lon1, az, s);
        // 1e-10 rad is 0.6 mm.
        assert!((lat - lat2).abs() < 1e-10 && (lon - lon2).abs() < 1e-10, "{lat} {lon}");
    }

    #[test]
    fn long_lines_there_and_back() {
        let e = Ellipsoid::WGS84;
        let (lat0, lon0) = (25f64.to_radians(), 45f64.to_radians());
        for az_deg in [0.0, 37.0, 90.0, 180.0, 251.0, 359.0] {
            for s in [1.0, 1.0e3, 1.0e5, 5.0e6, 1.0e7] {
                let (lat, lon) = direct(&e, lat0, lon0, f64::to_radians(az_deg), s);
                let (s2, az2) = inverse(&e, lat0, lon0, lat, lon).unwrap();
                assert!((s2 - s).abs() < 1e-4, "{az_deg} {s}: {s2}");
                let daz = (az2 - az_deg.to_radians() + std::f64::consts::PI)
                    .rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
                assert!(daz.abs() * s < 1e-4, "{az_deg} {s}: {az2}");
            }
        }
    }
}
