//! Running the inspector: in a window (eframe, drawing with OpenGL) or off-screen (egui_kittest
//! rendering with a wgpu device of its own on the replay's adapter) to write a screenshot of the
//! whole window once the worker has shown what was asked. Neither draws with the replay's device.

use std::path::Path;
use std::time::{Duration, Instant};

use eframe::egui_wgpu::{self, RenderState, WgpuConfiguration, WgpuSetup, WgpuSetupExisting};
use framelab_replay::GpuContext;
use framelab_replay::wgpu;

use crate::app::Inspector;

#[derive(Debug, thiserror::Error)]
pub enum HeadlessError {
    #[error("drawing with the replay device: {0}")]
    RenderState(String),
    #[error("the replay did not finish within {0:?}")]
    Timeout(Duration),
    #[error("the replay failed: {0}")]
    Replay(String),
    #[error("rendering the window: {0}")]
    Render(String),
    #[error("writing {path}: {message}")]
    Write { path: String, message: String },
    #[error("opening the window: {0}")]
    Window(String),
}

/// egui's renderer on a device of its own on the replay's adapter: the UI never submits to or
/// waits on the queue the replay uses, so a replay in flight never holds a frame up.
pub fn render_state(ctx: &GpuContext) -> Result<RenderState, HeadlessError> {
    let descriptor = wgpu::DeviceDescriptor {
        label: Some("framelab ui"),
        required_limits: ctx.adapter.limits(),
        ..Default::default()
    };
    let (device, queue) = pollster::block_on(ctx.adapter.request_device(&descriptor))
        .map_err(|e| HeadlessError::RenderState(e.to_string()))?;
    let config = WgpuConfiguration {
        wgpu_setup: WgpuSetup::Existing(WgpuSetupExisting {
            instance: ctx.instance.clone(),
            adapter: ctx.adapter.clone(),
            device,
            queue,
        }),
        ..Default::default()
    };
    pollster::block_on(RenderState::create(
        &config,
        &ctx.instance,
        None,
        egui_wgpu::RendererOptions::default(),
    ))
    .map_err(|e| HeadlessError::RenderState(e.to_string()))
}

/// Renders the inspector off-screen at `size` (points) once its worker is idle, waiting at
/// most `timeout`, and returns the image.
pub fn capture(
    app: Inspector,
    render_state: RenderState,
    size: egui::Vec2,
    timeout: Duration,
) -> Result<image::RgbaImage, HeadlessError> {
    // A screenshot is for the user: a widget's missing accessible name (which the tests'
    // harness checks) must not stop it.
    let mut harness = builder(size, render_state)
        .with_accessibility_check(false)
        .build_ui_state(|ui, app: &mut Inspector| app.ui(ui), app);
    settle(&mut harness, timeout)?;
    harness.render().map_err(HeadlessError::Render)
}

/// A kittest harness over the inspector, drawing with `render_state`.
pub fn harness(
    app: Inspector,
    render_state: RenderState,
    size: egui::Vec2,
) -> egui_kittest::Harness<'static, Inspector> {
    builder(size, render_state).build_ui_state(|ui, app: &mut Inspector| app.ui(ui), app)
}

fn builder(size: egui::Vec2, render_state: RenderState) -> egui_kittest::HarnessBuilder<Inspector> {
    egui_kittest::Harness::builder()
        .with_size(size)
        // A capture may name things in any script; missing glyphs draw as boxes.
        .allow_missing_glyphs()
        .renderer(egui_kittest::wgpu::WgpuTestRenderer::from_render_state(
            render_state,
        ))
}

/// Steps the harness until the worker has answered, finished its start and drawn every
/// thumbnail, and the UI has drawn it all.
pub fn settle(
    harness: &mut egui_kittest::Harness<'static, Inspector>,
    timeout: Duration,
) -> Result<(), HeadlessError> {
    let start = Instant::now();
    let mut quiet = 0;
    while quiet < 3 {
        harness.step();
        if let Some(e) = &harness.state().error {
            return Err(HeadlessError::Replay(e.clone()));
        }
        if harness.state().is_settled() {
            quiet += 1;
        } else {
            quiet = 0;
            std::thread::sleep(Duration::from_millis(20));
        }
        if start.elapsed() > timeout {
            return Err(HeadlessError::Timeout(timeout));
        }
    }
    Ok(())
}

/// Writes `image` as PNG, through a temporary file so a failed write leaves nothing behind.
pub fn save_png(image: &image::RgbaImage, path: &Path) -> Result<(), HeadlessError> {
    let err = |message: String| HeadlessError::Write {
        path: path.display().to_string(),
        message,
    };
    let mut bytes = Vec::new();
    image
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .map_err(|e| err(e.to_string()))?;
    framelab_core::atomic::write(path, &bytes).map_err(|e| err(e.to_string()))
}

/// Opens the inspector in a window drawn with OpenGL (eframe's glow renderer): the window's
/// drawing shares nothing with the replay's Vulkan device, and has no swapchain surface that a
/// window shown before its first resize could leave unconfigured.
pub fn window(
    title: &str,
    make: impl FnOnce() -> Inspector + 'static,
) -> Result<(), HeadlessError> {
    let options = eframe::NativeOptions {
        renderer: eframe::Renderer::Glow,
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([1600.0, 900.0])
            .with_min_inner_size([640.0, 400.0])
            .with_title(title),
        ..Default::default()
    };
    eframe::run_native(title, options, Box::new(move |_cc| Ok(Box::new(make()))))
        .map_err(|e| HeadlessError::Window(e.to_string()))
}
