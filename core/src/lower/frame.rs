//! Frame constants: view, projection and previous-frame matrices from the capture's camera,
//! moved by its velocity each frame and jittered by a Halton(2, 3) sequence (so temporal passes
//! and motion vectors have work), with time, resolution, sun and moon. Shaders declare any
//! subset of these members in a `frame` uniform struct; they are filled by name.
//!
//! The shadow cascades are fitted here, on the CPU, as an engine does: one matrix per cascade
//! (`csm_view_proj_0..3`), split distances in `csm_splits`, and the texel size of each cascade in
//! world units in `csm_texel` (shaders scale normal offsets and filter radii by it).

use crate::plan::Params;
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

/// The light that casts the cascades: the sun, or the moon once the sun is below the horizon.
fn shadow_light(capture: &Capture) -> Vec3 {
    let f = &capture.frame;
    let sun = Vec3::from(f.sun_direction).normalize_or_zero();
    if sun.y > 0.0 {
        sun
    } else {
        Vec3::from(f.moon_direction).normalize_or_zero()
    }
}

/// Practical split distances (Nvidia GPU Gems 3, ch. 10): a blend of logarithmic and uniform
/// splits between the near plane and the shadow distance.
fn cascade_splits(near: f32, far: f32, lambda: f32) -> [f32; 4] {
    let mut out = [0.0; 4];
    for (i, o) in out.iter_mut().enumerate() {
        let t = (i + 1) as f32 / 4.0;
        let log = near * (far / near).powf(t);
        let uniform = near + (far - near) * t;
        *o = lambda * log + (1.0 - lambda) * uniform;
    }
    out
}

/// One cascade: the bounding sphere of the frustum slice [`from`, `to`], so the cascade's size
/// does not change as the camera turns, and its centre snapped to whole shadow-map texels in
/// light space, so it does not shimmer as the camera moves.
fn cascade(capture: &Capture, view: &View, light: Vec3, from: f32, to: f32) -> (Mat4, f32) {
    let c = &capture.camera;
    let aspect = capture.width as f32 / capture.height.max(1) as f32;
    let tan_y = (c.fov_y_degrees.to_radians() * 0.5).tan();
    let tan_x = tan_y * aspect;
    let inv_view = view.view.inverse();
    let mut corners = Vec::with_capacity(8);
    for d in [from, to] {
        for (sx, sy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
            corners.push(inv_view.transform_point3(Vec3::new(sx * tan_x * d, sy * tan_y * d, -d)));
        }
    }
    let center = corners.iter().copied().sum::<Vec3>() / 8.0;
    let radius = corners
        .iter()
        .map(|p| p.distance(center))
        .fold(0.0f32, f32::max)
        .ceil()
        .max(1.0);
    let resolution = capture.frame.shadow_cascades.resolution.max(1) as f32;
    let texel = 2.0 * radius / resolution;
    let up = if light.y.abs() > 0.99 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    let light_view = Mat4::look_at_rh(Vec3::ZERO, -light, up);
    let mut c_ls = light_view.transform_point3(center);
    c_ls.x = (c_ls.x / texel).floor() * texel;
    c_ls.y = (c_ls.y / texel).floor() * texel;
    // Depth covers the sphere plus tall casters between it and the light.
    let depth = radius + 400.0;
    let proj = Mat4::orthographic_rh(
        c_ls.x - radius,
        c_ls.x + radius,
        c_ls.y - radius,
        c_ls.y + radius,
        -c_ls.z - depth,
        -c_ls.z + radius,
    );
    (proj * light_view, texel)
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
    let light = shadow_light(capture);
    p.insert("shadow_direction".into(), vec4(light.into(), 0.0));
    let cam = &capture.camera;
    let sc = &capture.frame.shadow_cascades;
    let splits = cascade_splits(cam.near, sc.max_distance.min(cam.far), sc.split_lambda);
    let mut texels = Vec::with_capacity(4);
    for (i, &to) in splits.iter().enumerate() {
        let from = if i == 0 { cam.near } else { splits[i - 1] };
        let (m, texel) = cascade(capture, &now, light, from, to);
        p.insert(format!("csm_view_proj_{i}"), mat(m));
        texels.push(f64::from(texel));
    }
    p.insert(
        "csm_splits".into(),
        splits.iter().map(|&x| f64::from(x)).collect(),
    );
    p.insert("csm_texel".into(), texels);
    // Top view: orthographic, looking straight down, centred under the camera.
    let e = capture.frame.top_view_extent;
    let eye = Vec3::new(now.position.x, 1000.0, now.position.z);
    let top = Mat4::orthographic_rh(-e, e, -e, e, 0.0, 2000.0)
        * Mat4::look_at_rh(eye, eye - Vec3::Y, Vec3::Z);
    p.insert("top_view_proj".into(), mat(top));
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
    fn cascade_splits_grow_to_the_shadow_distance() {
        let splits = cascade_splits(0.1, 200.0, 0.75);
        assert!(splits.windows(2).all(|w| w[0] < w[1]));
        assert!((splits[3] - 200.0).abs() < 1e-3);
        // Logarithmic weighting puts the first split far closer than a uniform quarter.
        assert!(splits[0] < 50.0 * 0.5);
    }

    /// As the camera moves, each cascade's projection of a fixed world point moves by whole
    /// shadow-map texels, so shadow edges do not crawl.
    #[test]
    fn cascades_move_in_whole_texels() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../captures/night_city/main_street_day.json");
        let capture = crate::pipeline::Validated::load(&path, &Default::default())
            .unwrap()
            .capture;
        let resolution = capture.frame.shadow_cascades.resolution as f32;
        let (a, b) = (constants(&capture, 0), constants(&capture, 7));
        for c in 0..4 {
            let key = format!("csm_view_proj_{c}");
            let m = |p: &Params| Mat4::from_cols_array(&std::array::from_fn(|i| p[&key][i] as f32));
            let (ma, mb) = (m(&a), m(&b));
            assert_ne!(ma, mb, "cascade {c} should follow the moving camera");
            for point in [
                Vec3::ZERO,
                Vec3::new(13.0, 2.0, -40.0),
                Vec3::new(-60.0, 30.0, 90.0),
            ] {
                let (pa, pb) = (ma.project_point3(point), mb.project_point3(point));
                let texels = (pb - pa).truncate() * resolution * 0.5;
                for d in [texels.x, texels.y] {
                    assert!(
                        (d - d.round()).abs() < 0.05,
                        "cascade {c}: moved {d} texels"
                    );
                }
            }
        }
    }

    #[test]
    fn halton_sequence() {
        assert_eq!(halton(1, 2), 0.5);
        assert_eq!(halton(2, 2), 0.25);
        assert!((halton(1, 3) - 1.0 / 3.0).abs() < 1e-6);
    }
}
