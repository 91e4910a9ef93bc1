//! How it works: the viewer's flight controls, free of any window. Keys held move the camera each
//! frame by speed × elapsed time: W/S (or ↑/↓) along the view, A/D (or ←/→) sideways on the level,
//! E/Space up and Q/Ctrl down; Shift boosts tenfold. Dragging turns the view (heading and pitch,
//! pitch kept short of straight up or down). The speed spans 1 m/s to 1000 km/s in steps of a
//! quarter (scroll) or doubles and halves (+/−). By height (V), the speed is the one set at
//! `PACE_HEIGHT_M` above the ground and scales with the height above it, so one setting flies
//! from orbit down to the ground: a tenth as fast ten times lower. Ground-follow keeps the height
//! above the ground the camera had when it was switched on (up and down then change that height).
//! Keys that do something once (reset, next view, screenshot…) come back as an `Action` for the
//! viewer.

use glam::DVec3;
use winit::keyboard::KeyCode;

use terramp::camera::Camera;

/// Slowest speed offered, m/s.
pub const MIN_SPEED_M_S: f64 = 1.0;
/// Fastest speed offered, m/s (1000 km/s).
pub const MAX_SPEED_M_S: f64 = 1.0e6;
/// Speed factor while Shift is held.
const BOOST: f64 = 10.0;
/// One scroll notch multiplies the speed by this (or divides).
const SCROLL_STEP: f64 = 1.25;
/// Degrees turned per pixel dragged.
const TURN_DEG_PER_PX: f64 = 0.2;
/// The pitch stays this far from straight up or down, degrees (the heading stays defined).
const PITCH_LIMIT_DEG: f64 = 89.0;
/// Least height above the ground ground-follow holds, metres.
const MIN_FOLLOW_M: f64 = 1.0;
/// By height, the speed set is the speed this high above the ground, metres.
pub const PACE_HEIGHT_M: f64 = 1000.0;
/// By height, the speed never slows below the one this high above the ground, metres.
const MIN_PACE_ABOVE_M: f64 = 0.5;

/// What a key asks of the viewer, beyond moving.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// R: back to the dataset's overview.
    Reset,
    /// Tab: the next of the preset views.
    NextView,
    /// F12: a screenshot and the settings that reproduce it.
    Screenshot,
    /// P: start or stop recording the flown path.
    Record,
    /// H or F1: show or hide the overlay.
    Overlay,
    /// Escape: close the viewer.
    Quit,
}

/// Movement keys held: forward, right, up, each −1, 0 or +1 once opposites cancel.
#[derive(Debug, Default, Clone, Copy)]
struct Held {
    forward: [bool; 2],
    right: [bool; 2],
    up: [bool; 2],
    boost: bool,
}

fn axis([plus, minus]: [bool; 2]) -> f64 {
    f64::from(u8::from(plus)) - f64::from(u8::from(minus))
}

/// The camera a person flies.
#[derive(Debug, Clone)]
pub struct Flight {
    /// The pose now.
    pub camera: Camera,
    /// Speed without boost, m/s.
    pub speed_m_s: f64,
    /// Height above the ground held, metres, when ground-follow is on.
    pub follow_m: Option<f64>,
    /// The speed scales with the height above the ground (`PACE_HEIGHT_M`).
    pub by_height: bool,
    /// The height above the ground (above the datum off the dataset) at the last step, metres.
    above_m: f64,
    held: Held,
}

impl Flight {
    /// A flight starting at `camera`, at a speed that crosses `span_m` in about a minute.
    pub fn new(camera: Camera, span_m: f64) -> Self {
        let speed_m_s = (span_m / 60.0).clamp(MIN_SPEED_M_S, MAX_SPEED_M_S);
        let above_m = camera.position_m.z;
        Self { camera, speed_m_s, follow_m: None, by_height: false, above_m, held: Held::default() }
    }

    /// The speed moving now (boost and height included), m/s.
    pub fn moving_speed_m_s(&self) -> f64 {
        let boost = if self.held.boost { BOOST } else { 1.0 };
        let pace = if self.by_height { self.above_m.max(MIN_PACE_ABOVE_M) / PACE_HEIGHT_M } else { 1.0 };
        (self.speed_m_s * boost * pace).min(MAX_SPEED_M_S)
    }

    /// A key pressed or released; keys that act once act on the press.
    pub fn key(&mut self, code: KeyCode, pressed: bool) -> Option<Action> {
        let h = &mut self.held;
        match code {
            KeyCode::KeyW | KeyCode::ArrowUp => h.forward[0] = pressed,
            KeyCode::KeyS | KeyCode::ArrowDown => h.forward[1] = pressed,
            KeyCode::KeyD | KeyCode::ArrowRight => h.right[0] = pressed,
            KeyCode::KeyA | KeyCode::ArrowLeft => h.right[1] = pressed,
            KeyCode::KeyE | KeyCode::Space => h.up[0] = pressed,
            KeyCode::KeyQ | KeyCode::ControlLeft | KeyCode::ControlRight => h.up[1] = pressed,
            KeyCode::ShiftLeft | KeyCode::ShiftRight => h.boost = pressed,
            _ if !pressed => {}
            KeyCode::Equal | KeyCode::NumpadAdd => self.scale_speed(2.0),
            KeyCode::Minus | KeyCode::NumpadSubtract => self.scale_speed(0.5),
            KeyCode::KeyR => return Some(Action::Reset),
            KeyCode::Tab => return Some(Action::NextView),
            KeyCode::F12 => return Some(Action::Screenshot),
            KeyCode::KeyP => return Some(Action::Record),
            KeyCode::KeyH | KeyCode::F1 => return Some(Action::Overlay),
            KeyCode::KeyV => self.by_height = !self.by_height,
            KeyCode::Escape => return Some(Action::Quit),
            _ => {}
        }
        None
    }

    /// Forgets every key held (the window lost focus: their releases will not come).
    pub fn release_all(&mut self) {
        self.held = Held::default();
    }

    /// Scroll by `notches` (positive: faster).
    pub fn scroll(&mut self, notches: f64) {
        self.scale_speed(SCROLL_STEP.powf(notches));
    }

    fn scale_speed(&mut self, factor: f64) {
        self.speed_m_s = (self.speed_m_s * factor).clamp(MIN_SPEED_M_S, MAX_SPEED_M_S);
    }

    /// Turns the view by a drag of (`dx_px`, `dy_px`): right turns right, down looks down.
    pub fn drag(&mut self, dx_px: f64, dy_px: f64) {
        let c = &mut self.camera;
        c.yaw_deg = (c.yaw_deg + dx_px * TURN_DEG_PER_PX).rem_euclid(360.0);
        c.pitch_deg = (c.pitch_deg - dy_px * TURN_DEG_PER_PX).clamp(-PITCH_LIMIT_DEG, PITCH_LIMIT_DEG);
    }

    /// Switches ground-follow, holding the height above `ground_m` (the ground under the camera,
    /// if known) from now on.
    pub fn toggle_follow(&mut self, ground_m: Option<f64>) {
        self.follow_m = match (self.follow_m, ground_m) {
            (None, Some(g)) => Some((self.camera.position_m.z - g).max(MIN_FOLLOW_M)),
            _ => None,
        };
    }

    /// Moves for `dt_s` seconds with the keys held; `ground_m` gives the ground's height under a
    /// CRS position (for ground-follow), `None` off the dataset. Returns whether the pose changed.
    pub fn step(&mut self, dt_s: f64, ground_m: impl Fn(f64, f64) -> Option<f64>) -> bool {
        let h = self.held;
        let (forward, right, up) = (axis(h.forward), axis(h.right), axis(h.up));
        let p = self.camera.position_m;
        self.above_m = p.z - ground_m(p.x, p.y).unwrap_or(0.0);
        let step_m = self.moving_speed_m_s() * dt_s.max(0.0);
        let yaw = self.camera.yaw_deg.to_radians();
        let level_right = DVec3::new(yaw.cos(), -yaw.sin(), 0.0);
        let mut delta = (self.camera.forward() * forward + level_right * right) * step_m;
        match self.follow_m.as_mut() {
            // Following, up and down change the height held, the ground sets the rest.
            Some(follow) => *follow = (*follow + up * step_m).max(MIN_FOLLOW_M),
            None => delta.z += up * step_m,
        }
        let before = self.camera.position_m;
        self.camera.position_m += delta;
        let p = self.camera.position_m;
        if let (Some(follow), Some(g)) = (self.follow_m, ground_m(p.x, p.y)) {
            self.camera.position_m.z = g + follow;
        }
        self.camera.position_m != before
    }

    /// Takes the renderer's lift of a camera under the ground, so the flight does not keep
    /// pushing into it.
    pub fn lifted(&mut self, lift_m: f64) {
        if lift_m > 0.0 {
            self.camera.position_m.z += lift_m;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flight() -> Flight {
        let camera = Camera {
            position_m: DVec3::new(1000.0, 2000.0, 500.0),
            yaw_deg: 90.0,
            pitch_deg: 0.0,
            roll_deg: 0.0,
            fov_deg: 60.0,
            near_m: 0.1,
        };
        Flight::new(camera, 6000.0)
    }

    #[test]
    fn keys_move_along_the_view_sideways_and_up_at_the_speed_shown() {
        let mut f = flight();
        assert_eq!(f.speed_m_s, 100.0);
        // Heading east: forward is +x, right is −y (south).
        f.key(KeyCode::KeyW, true);
        assert!(f.step(1.0, |_, _| None));
        assert!((f.camera.position_m - DVec3::new(1100.0, 2000.0, 500.0)).length() < 1e-9);
        f.key(KeyCode::KeyW, false);
        f.key(KeyCode::KeyD, true);
        f.key(KeyCode::ShiftLeft, true);
        f.step(0.5, |_, _| None);
        assert!((f.camera.position_m - DVec3::new(1100.0, 1500.0, 500.0)).length() < 1e-9);
        f.release_all();
        f.key(KeyCode::Space, true);
        f.key(KeyCode::KeyQ, true);
        assert!(!f.step(1.0, |_, _| None), "up and down cancel");
    }

    #[test]
    fn the_speed_spans_one_metre_to_a_thousand_kilometres_a_second() {
        let mut f = flight();
        for _ in 0..200 {
            f.scroll(1.0);
        }
        assert_eq!(f.speed_m_s, MAX_SPEED_M_S);
        f.key(KeyCode::ShiftLeft, true);
        assert_eq!(f.moving_speed_m_s(), MAX_SPEED_M_S);
        for _ in 0..40 {
            f.key(KeyCode::Minus, true);
        }
        assert_eq!(f.speed_m_s, MIN_SPEED_M_S);
        f.key(KeyCode::Equal, true);
        assert_eq!(f.speed_m_s, 2.0);
    }

    #[test]
    fn dragging_turns_and_the_pitch_stops_short_of_vertical() {
        let mut f = flight();
        f.drag(-500.0, 0.0);
        assert!((f.camera.yaw_deg - 350.0).abs() < 1e-9);
        f.drag(0.0, 10_000.0);
        assert_eq!(f.camera.pitch_deg, -PITCH_LIMIT_DEG);
    }

    #[test]
    fn ground_follow_holds_the_height_above_the_ground_and_up_changes_it() {
        let mut f = flight();
        let ground = |x: f64, _: f64| Some(x * 0.1);
        f.toggle_follow(ground(1000.0, 0.0));
        assert_eq!(f.follow_m, Some(400.0));
        f.key(KeyCode::KeyW, true);
        f.step(1.0, ground);
        assert!((f.camera.position_m.z - (110.0 + 400.0)).abs() < 1e-9);
        f.key(KeyCode::KeyW, false);
        f.key(KeyCode::KeyE, true);
        f.step(1.0, ground);
        assert_eq!(f.follow_m, Some(500.0));
        f.toggle_follow(Some(0.0));
        assert_eq!(f.follow_m, None);
    }

    #[test]
    fn by_height_the_speed_scales_with_the_height_above_the_ground() {
        let mut f = flight();
        f.key(KeyCode::KeyV, true);
        assert!(f.by_height);
        // 100 m/s set: 50 m/s at 500 m above the ground, 2 m/s at 20 m.
        let ground = |_: f64, _: f64| Some(0.0);
        f.key(KeyCode::KeyW, true);
        f.step(1.0, ground);
        assert!((f.camera.position_m.x - 1050.0).abs() < 1e-9, "{}", f.camera.position_m);
        assert!((f.moving_speed_m_s() - 50.0).abs() < 1e-9);
        f.camera.position_m.z = 20.0;
        f.step(1.0, ground);
        assert!((f.camera.position_m.x - 1052.0).abs() < 1e-9);
        // Over ground 480 m high, the same 20 m above it; off the dataset, above the datum.
        f.camera.position_m.z = 500.0;
        f.step(1.0, |_, _| Some(480.0));
        assert!((f.camera.position_m.x - 1054.0).abs() < 1e-9);
        f.step(1.0, |_, _| None);
        assert!((f.camera.position_m.x - 1104.0).abs() < 1e-9);
        // At the ground it slows to the speed half a metre up, not to a stop.
        f.step(1.0, |_, _| Some(500.0));
        assert!((f.camera.position_m.x - 1104.05).abs() < 1e-9);
        f.key(KeyCode::KeyV, true);
        f.step(1.0, ground);
        assert!((f.camera.position_m.x - 1204.05).abs() < 1e-9);
    }

    #[test]
    fn keys_that_act_once_act_on_the_press() {
        let mut f = flight();
        assert_eq!(f.key(KeyCode::F12, true), Some(Action::Screenshot));
        assert_eq!(f.key(KeyCode::F12, false), None);
        assert_eq!(f.key(KeyCode::Tab, true), Some(Action::NextView));
        assert_eq!(f.key(KeyCode::KeyR, true), Some(Action::Reset));
    }
}
