//! Degenerate inputs get a typed error or a clamped frame, never a panic: viewports of no area or
//! beyond the adapter's targets, fields of view at and past their bounds (0.01°, just under 180°),
//! non-finite and absurd cameras (after which the renderer goes on as before), and a camera inside
//! the terrain, which is lifted above it.

use glam::DVec3;
use terramp::camera::{Camera, CameraError, MAX_COORDINATE_M, MIN_FOV_DEG, MIN_NEAR_M};
use terramp::dataset::Dataset;
use terramp::frame::{GROUND_CLEARANCE_NEAR, RenderError, Renderer};
use terramp::reference::worst::max_or_nan;

use terramp_testkit::audit::{Dem, Tolerance, audit, camera_at};
use terramp_testkit::small_settings;

#[test]
fn viewports_of_no_area_or_too_large_are_errors() {
    let dataset = terramp_testkit::synth_dataset(64, 7);
    let open =
        |w, h| Renderer::new(terramp_testkit::gpu(), Dataset::open(&dataset).unwrap(), small_settings(w, h));
    for (w, h) in [(0, 180), (320, 0), (0, 0)] {
        assert!(matches!(open(w, h), Err(RenderError::Camera(CameraError::Viewport(..)))), "{w}×{h}");
    }
    assert!(matches!(open(1 << 20, 8), Err(RenderError::ViewportTooLarge { .. })));
    // A cache of more slots than a texture array holds is named, not a GPU validation error.
    let mut settings = small_settings(64, 64);
    settings.cache.imagery_slots = terramp_testkit::gpu().device.limits().max_texture_array_layers + 1;
    let error =
        Renderer::new(terramp_testkit::gpu(), Dataset::open(&dataset).unwrap(), settings).err().unwrap();
    assert!(matches!(error, RenderError::CacheTooLarge { key: "imagery_slots", .. }), "{error}");
    assert!(error.to_string().starts_with("cache.imagery_slots = "), "{error}");
    // One pixel is a viewport.
    let mut r = open(1, 1).unwrap();
    let dem = Dem::load(&r.dataset);
    let camera = camera_at(&r, &dem, [300.0, 300.0], 50.0, 0.0, -45.0);
    r.render_resolved(&camera).unwrap();
    assert_eq!(r.read_depth().unwrap().len(), 1);
    assert!(r.read_depth().unwrap()[0] > 0.0, "the one pixel looks at the ground");
}

/// Elevation angle, degrees, of the terrain's silhouette seen from grid point `eye` towards
/// `yaw_deg` (the finest mesh, marched an eighth of a spacing at a time), and where it is.
fn silhouette(dem: &Dem, eye: DVec3, yaw_deg: f64) -> (f64, [f64; 2]) {
    let (sin, cos) = yaw_deg.to_radians().sin_cos();
    let (mut best, mut t) = ((-90.0f64, [eye.x, eye.y]), dem.spacing_m);
    while dem.covers(eye.x + sin * t, eye.y + cos * t, 0.0) {
        let p = [eye.x + sin * t, eye.y + cos * t];
        let angle = (dem.mesh_height_m(p[0], p[1]) - eye.z).atan2(t).to_degrees();
        if angle > best.0 {
            best = (angle, p);
        }
        t += 0.125 * dem.spacing_m;
    }
    best
}

#[test]
fn fields_of_view_near_0_and_180_render_or_are_refused() {
    let dataset = terramp_testkit::synth_dataset(256, 7);
    let mut r = terramp_testkit::renderer(&dataset, small_settings(320, 180));
    let dem = Dem::load(&r.dataset);
    let span = dem.span_m();
    let level = camera_at(&r, &dem, [0.3 * span[0], 0.3 * span[1]], 20.0, 45.0, 0.0);
    for fov_deg in [0.0, 0.5 * MIN_FOV_DEG, 180.0, 200.0, -10.0] {
        let camera = Camera { fov_deg, ..level };
        assert!(matches!(r.render(&camera), Err(RenderError::Camera(CameraError::Fov(_)))), "{fov_deg}°");
    }
    // The narrowest view centred on a silhouette: ground below it, sky above, a fraction of a metre
    // of ridge across the frame, every pixel where the rays say.
    let o = r.dataset.manifest.origin_m;
    let eye = level.position_m - DVec3::new(o[0], o[1], 0.0);
    let (pitch_deg, yaw_deg) = (0..24)
        .map(|k| f64::from(k) * 15.0)
        .find_map(|yaw| {
            let (pitch, at) = silhouette(&dem, eye, yaw);
            dem.covers(at[0], at[1], 200.0).then_some((pitch, yaw))
        })
        .expect("a silhouette inside the dataset");
    let ridge = Camera { fov_deg: MIN_FOV_DEG, pitch_deg, yaw_deg, ..level };
    // At 179.999° the rectilinear image squeezes everything within 89.99° of the axis into the
    // middle pixel and the near plane clips the rest: the frame is sky, and that is right.
    let wide = Camera { fov_deg: 179.999, pitch_deg: -10.0, ..level };
    // (what, camera, the mesh's tolerance, whether most rays can be judged)
    let views = [
        ("narrowest, on a ridge", ridge, 0.01, true),
        ("170°", Camera { fov_deg: 170.0, ..wide }, 0.05, true),
        ("179.999°", wide, 0.05, false),
    ];
    for (what, camera, height_m, judged) in views {
        r.render_resolved(&camera).unwrap();
        let a = audit(&r, &camera, &dem, Tolerance::flat(height_m, 20.0), 4);
        println!("{what}: {a:?}");
        a.assert_sound(what);
        if judged {
            assert!(a.expect_ground > a.rays / 5 && a.expect_sky > a.rays / 5, "{what}: {a:?}");
        }
    }
}

/// How far (pixels) the GPU's f32 projection puts points 1 km away on the rays through pixel
/// centres of a 1920×1080 frame from where they belong, at `fov_deg`.
fn worst_f32_misplacement_px(fov_deg: f64) -> f64 {
    let camera = Camera {
        position_m: DVec3::ZERO,
        yaw_deg: 30.0,
        pitch_deg: -5.0,
        roll_deg: 0.0,
        fov_deg,
        near_m: 0.1,
    };
    let clip = camera.clip_from_view(1920, 1080).unwrap() * camera.view_from_world();
    let (inverse, clip_f32) = (clip.inverse(), clip.as_mat4());
    let mut worst_px = 0.0f64;
    for row in (0..1080).step_by(7) {
        for column in (0..1920).step_by(13) {
            let ndc = [(f64::from(column) + 0.5) / 960.0 - 1.0, 1.0 - (f64::from(row) + 0.5) / 540.0];
            let near = inverse * glam::DVec4::new(ndc[0], ndc[1], 1.0, 1.0);
            let point = (near.truncate() / near.w).normalize() * 1000.0;
            let p = clip_f32 * point.as_vec3().extend(1.0);
            let (x, y) = (f64::from(p.x / p.w), f64::from(p.y / p.w));
            worst_px =
                max_or_nan(max_or_nan(worst_px, ((x - ndc[0]) * 960.0).abs()), ((y - ndc[1]) * 540.0).abs());
        }
    }
    worst_px
}

#[test]
fn the_narrowest_field_of_view_keeps_pixels_in_place_in_f32() {
    let (at_min, narrower) =
        (worst_f32_misplacement_px(MIN_FOV_DEG), worst_f32_misplacement_px(0.1 * MIN_FOV_DEG));
    println!(
        "1080 rows: f32 misplaces points by {at_min:.2} px at {MIN_FOV_DEG}°, {narrower:.2} px at a tenth of it"
    );
    assert!(at_min < 1.0, "{at_min} px");
    // The bound is where it matters: ten times narrower, pixels land elsewhere.
    assert!(narrower > 1.0, "{narrower} px");
}

#[test]
fn non_finite_and_absurd_cameras_are_errors_and_the_renderer_goes_on() {
    let dataset = terramp_testkit::synth_dataset(256, 7);
    let mut r = terramp_testkit::renderer(&dataset, small_settings(160, 90));
    let dem = Dem::load(&r.dataset);
    let good = camera_at(&r, &dem, [800.0, 900.0], 30.0, 60.0, -10.0);
    r.render_resolved(&good).unwrap();
    let before = r.read_colour().unwrap();
    let position = |x, y, z| Camera { position_m: DVec3::new(x, y, z), ..good };
    let (nan, inf) = (f64::NAN, f64::INFINITY);
    let p = good.position_m;
    let bad = [
        (position(nan, p.y, p.z), CameraError::NotFinite("x")),
        (position(p.x, -inf, p.z), CameraError::NotFinite("y")),
        (position(p.x, p.y, inf), CameraError::NotFinite("z")),
        (Camera { yaw_deg: nan, ..good }, CameraError::NotFinite("yaw")),
        (Camera { pitch_deg: -inf, ..good }, CameraError::NotFinite("pitch")),
        (Camera { fov_deg: nan, ..good }, CameraError::NotFinite("fov")),
        (Camera { near_m: inf, ..good }, CameraError::NotFinite("near")),
        (Camera { near_m: 0.0, ..good }, CameraError::Near(0.0)),
        (Camera { near_m: -1.0, ..good }, CameraError::Near(-1.0)),
        (Camera { near_m: 0.5 * MIN_NEAR_M, ..good }, CameraError::Near(0.5 * MIN_NEAR_M)),
        (position(1e30, p.y, p.z), CameraError::TooFar("x", 1e30)),
        (position(p.x, -2.0 * MAX_COORDINATE_M, p.z), CameraError::TooFar("y", -2.0 * MAX_COORDINATE_M)),
        (position(p.x, p.y, 1e300), CameraError::TooFar("z", 1e300)),
    ];
    for (camera, expected) in bad {
        match r.render(&camera) {
            Err(RenderError::Camera(error)) => assert_eq!(error, expected),
            other => panic!("{camera:?}: {other:?}"),
        }
        assert!(r.render_resolved(&camera).is_err());
    }
    // Far but legal: nothing to see, nothing broken.
    for camera in [position(MAX_COORDINATE_M, -MAX_COORDINATE_M, 1e6), Camera { pitch_deg: 1e300, ..good }] {
        r.render(&camera).unwrap();
        let depth = r.read_depth().unwrap();
        assert!(depth.iter().all(|d| d.is_finite() && (0.0..=1.0).contains(d)), "{camera:?}");
    }
    r.render_resolved(&good).unwrap();
    assert!(r.read_colour().unwrap() == before, "the renderer changed after the bad cameras");
}

#[test]
fn a_camera_inside_the_terrain_is_lifted_above_it() {
    let dataset = terramp_testkit::synth_dataset(256, 7);
    let mut r = terramp_testkit::renderer(&dataset, small_settings(320, 180));
    let dem = Dem::load(&r.dataset);
    let span = dem.span_m();
    let spot = [0.55 * span[0], 0.45 * span[1]];
    let clearance_m = GROUND_CLEARANCE_NEAR * 0.1;
    for below_m in [0.05, 20.0, 5000.0] {
        let buried = camera_at(&r, &dem, spot, -below_m, 120.0, -10.0);
        let (report, _) = r.render_resolved(&buried).unwrap();
        let lifted_m = report.camera_lifted_m;
        assert!((lifted_m - (below_m + clearance_m)).abs() < 1e-3, "{below_m} m under: lifted {lifted_m} m");
        // The frame is the one seen from the lifted camera, and it is sound.
        let lifted = Camera { position_m: buried.position_m + DVec3::Z * lifted_m, ..buried };
        let image = r.read_colour().unwrap();
        let a = audit(&r, &lifted, &dem, Tolerance::flat(0.05, 20.0), 4);
        println!("{below_m} m under: {a:?}");
        a.assert_sound(&format!("{below_m} m under"));
        assert!(a.expect_ground > 100, "{a:?}");
        let (report, _) = r.render_resolved(&lifted).unwrap();
        assert!(report.camera_lifted_m < 1e-9, "lifted again by {} m", report.camera_lifted_m);
        assert!(r.read_colour().unwrap() == image, "{below_m} m under: not the lifted camera's frame");
    }
    // Above the ground, or beside the dataset at any height, nobody is lifted.
    let above = camera_at(&r, &dem, spot, 0.5, 120.0, -10.0);
    assert_eq!(r.render(&above).unwrap().camera_lifted_m, 0.0);
    let o = r.dataset.manifest.origin_m;
    let beside = Camera { position_m: DVec3::new(o[0] - 100.0, o[1] + 500.0, -1000.0), ..above };
    assert_eq!(r.render(&beside).unwrap().camera_lifted_m, 0.0);
}
