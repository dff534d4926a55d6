//! Frame constants: view, projection and previous-frame matrices from the capture's camera,
//! moved by its velocity each frame and jittered by a Halton(2, 3) sequence (so temporal passes
//! and motion vectors have work), with time, resolution, sun and moon. Shaders declare any
//! subset of these members in a `frame` uniform struct; they are filled by name.

use framelab_replay::plan::Params;
use glam::{Mat4, Vec3};

use crate::capture::Capture;

fn halton(index: u32, base: u32) -> f32 {
    let (mut f, mut r, mut i) = (1.0f32, 0.0f32, index);
    while i > 0 {
        f /= base as f32;
        r += f * (i % base) as f32;
        i /= base;
    }
    r
}

struct View {
    view: Mat4,
    proj: Mat4,
    position: Vec3,
    jitter: (f32, f32),
}

fn view_at(capture: &Capture, frame: u32) -> View {
    let c = &capture.camera;
    let offset = Vec3::from(c.velocity) * frame as f32;
    let position = Vec3::from(c.position) + offset;
    let target = Vec3::from(c.target) + offset;
    let view = Mat4::look_at_rh(position, target, Vec3::from(c.up));
    let aspect = capture.width as f32 / capture.height.max(1) as f32;
    let mut proj = Mat4::perspective_rh(c.fov_y_degrees.to_radians(), aspect, c.near, c.far);
    let jitter = if c.jitter_phases == 0 {
        (0.0, 0.0)
    } else {
        let i = frame % c.jitter_phases + 1;
        (
            (halton(i, 2) - 0.5) / capture.width as f32 * 2.0,
            (halton(i, 3) - 0.5) / capture.height as f32 * 2.0,
        )
    };
    proj.z_axis.x += jitter.0;
    proj.z_axis.y += jitter.1;
    View {
        view,
        proj,
        position,
        jitter,
    }
}

fn mat(m: Mat4) -> Vec<f64> {
    m.to_cols_array().iter().map(|&x| f64::from(x)).collect()
}

fn vec4(v: [f32; 3], w: f32) -> Vec<f64> {
    vec![
        f64::from(v[0]),
        f64::from(v[1]),
        f64::from(v[2]),
        f64::from(w),
    ]
}

/// The constants of replayed frame `frame` (0-based).
pub fn constants(capture: &Capture, frame: u32) -> Params {
    let now = view_at(capture, frame);
    let before = view_at(capture, frame.saturating_sub(1));
    let view_proj = now.proj * now.view;
    let unjittered = {
        let mut p = now.proj;
        p.z_axis.x -= now.jitter.0;
        p.z_axis.y -= now.jitter.1;
        p * now.view
    };
    let f = &capture.frame;
    let sun = Vec3::from(f.sun_direction).normalize_or_zero();
    let moon = Vec3::from(f.moon_direction).normalize_or_zero();
    let (w, h) = (capture.width as f32, capture.height as f32);
    let time = f.time_seconds + f.delta_seconds * frame as f32;
    let mut p = Params::new();
    p.insert("view".into(), mat(now.view));
    p.insert("proj".into(), mat(now.proj));
    p.insert("view_proj".into(), mat(view_proj));
    p.insert("inv_view_proj".into(), mat(view_proj.inverse()));
    p.insert("view_proj_unjittered".into(), mat(unjittered));
    p.insert("prev_view_proj".into(), mat(before.proj * before.view));
    p.insert("camera_position".into(), vec4(now.position.into(), 1.0));
    p.insert("sun_direction".into(), vec4(sun.into(), 0.0));
    p.insert("sun_color".into(), vec4(f.sun_color, 1.0));
    p.insert("moon_direction".into(), vec4(moon.into(), 0.0));
    p.insert("moon_color".into(), vec4(f.moon_color, 1.0));
    p.insert(
        "resolution".into(),
        vec![
            f64::from(w),
            f64::from(h),
            f64::from(1.0 / w),
            f64::from(1.0 / h),
        ],
    );
    p.insert(
        "jitter".into(),
        vec![
            f64::from(now.jitter.0),
            f64::from(now.jitter.1),
            f64::from(before.jitter.0),
            f64::from(before.jitter.1),
        ],
    );
    p.insert(
        "time".into(),
        vec![
            f64::from(time),
            f64::from(f.delta_seconds),
            f64::from(frame),
            f64::from(f.exposure),
        ],
    );
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halton_sequence() {
        assert_eq!(halton(1, 2), 0.5);
        assert_eq!(halton(2, 2), 0.25);
        assert!((halton(1, 3) - 1.0 / 3.0).abs() < 1e-6);
    }
}
