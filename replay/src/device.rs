//! Headless device acquisition: one wgpu instance without a window, adapter choice by name or by
//! preference (a real GPU before a software rasterizer), and a device with exactly the optional
//! features that the caller asks for and the adapter has.
//!
//! Choosing is separated from opening so the command can print every adapter it saw and say why
//! one was picked, which matters on CI machines where the only adapter is Mesa's lavapipe.

use std::fmt;

/// What the command line and the timing reports need to know about an adapter.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AdapterSummary {
    pub name: String,
    pub backend: String,
    pub device_type: wgpu::DeviceType,
    pub driver: String,
    pub driver_info: String,
}

impl AdapterSummary {
    fn from_info(info: &wgpu::AdapterInfo) -> Self {
        Self {
            name: info.name.clone(),
            backend: format!("{:?}", info.backend).to_lowercase(),
            device_type: info.device_type,
            driver: info.driver.clone(),
            driver_info: info.driver_info.clone(),
        }
    }
}

impl fmt::Display for AdapterSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} ({}, {}",
            self.name,
            self.backend,
            device_type_name(self.device_type)
        )?;
        if !self.driver.is_empty() {
            write!(f, ", {}", self.driver)?;
            if !self.driver_info.is_empty() {
                write!(f, " {}", self.driver_info)?;
            }
        }
        write!(f, ")")
    }
}

fn device_type_name(t: wgpu::DeviceType) -> &'static str {
    match t {
        wgpu::DeviceType::DiscreteGpu => "discrete GPU",
        wgpu::DeviceType::IntegratedGpu => "integrated GPU",
        wgpu::DeviceType::VirtualGpu => "virtual GPU",
        wgpu::DeviceType::Cpu => "software (CPU)",
        wgpu::DeviceType::Other => "other",
    }
}

/// Lower is better: real hardware first, software rasterizers last.
fn preference(t: wgpu::DeviceType) -> u8 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

#[derive(Debug, thiserror::Error)]
pub enum DeviceError {
    #[error(
        "no GPU adapter found (looked at backends {backends}); on a machine without a GPU install \
         Mesa's software Vulkan: apt-get install mesa-vulkan-drivers libvulkan1"
    )]
    NoAdapter { backends: String },
    #[error("no adapter matches {requested:?}; available: {}", available.join(", "))]
    NoMatchingAdapter {
        requested: String,
        available: Vec<String>,
    },
    #[error("adapter {adapter} refused to open a device: {source}")]
    RequestDevice {
        adapter: String,
        #[source]
        source: wgpu::RequestDeviceError,
    },
}

/// An open device and the adapter it came from.
#[derive(Debug)]
pub struct GpuContext {
    /// The instance the adapter came from: a window drawing with this device needs it.
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub summary: AdapterSummary,
    /// Features the caller asked for that this adapter lacks; the caller decides which pass
    /// needs each and reports it, because only the caller knows the passes.
    pub missing_features: wgpu::Features,
    /// Errors no error scope caught, and the reason the device was lost, if it was. wgpu's
    /// default handler panics; framelab records them and reports them instead.
    pub faults: Faults,
}

/// Errors recorded outside error scopes and device loss.
#[derive(Clone, Debug, Default)]
pub struct Faults {
    uncaptured: std::sync::Arc<std::sync::Mutex<Vec<String>>>,
    lost: std::sync::Arc<std::sync::Mutex<Option<String>>>,
}

impl Faults {
    /// Takes the errors recorded since the last call.
    pub fn take_uncaptured(&self) -> Vec<String> {
        self.uncaptured
            .lock()
            .map(|mut v| std::mem::take(&mut *v))
            .unwrap_or_default()
    }
    pub fn lost(&self) -> Option<String> {
        self.lost.lock().ok().and_then(|l| l.clone())
    }
}

fn instance(backends: wgpu::Backends) -> wgpu::Instance {
    let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    // WGPU_BACKEND, when set, chooses; otherwise only the backends asked for are started.
    if std::env::var_os("WGPU_BACKEND").is_none() {
        descriptor.backends = backends;
    }
    wgpu::Instance::new(descriptor)
}

/// Adapters of the native backends (Vulkan, Metal, DX12), or of OpenGL only when there are
/// none: starting the GL backend probes EGL, which on a headless machine prints errors of its
/// own to stderr that users would take for framelab's.
fn adapters() -> (wgpu::Instance, Vec<wgpu::Adapter>) {
    let native = instance(wgpu::Backends::PRIMARY);
    let found = pollster::block_on(native.enumerate_adapters(wgpu::Backends::all()));
    if !found.is_empty() {
        return (native, found);
    }
    let gl = instance(wgpu::Backends::all());
    let found = pollster::block_on(gl.enumerate_adapters(wgpu::Backends::all()));
    (gl, found)
}

/// Every adapter wgpu can see, best first; ties keep wgpu's order.
pub fn list_adapters() -> Vec<AdapterSummary> {
    let (_instance, mut adapters) = adapters();
    adapters.sort_by_key(|a| preference(a.get_info().device_type));
    adapters
        .iter()
        .map(|a| AdapterSummary::from_info(&a.get_info()))
        .collect()
}

/// Opens a device on the adapter whose name contains `name_filter` (case-insensitive) or, with
/// no filter, on the most preferred adapter. `wanted` features are requested where available and
/// the rest are returned in [`GpuContext::missing_features`].
pub fn open_device(
    name_filter: Option<&str>,
    wanted: wgpu::Features,
) -> Result<GpuContext, DeviceError> {
    let (instance, mut adapters) = adapters();
    if adapters.is_empty() {
        return Err(DeviceError::NoAdapter {
            backends: format!("{:?}", wgpu::Backends::all()),
        });
    }
    adapters.sort_by_key(|a| preference(a.get_info().device_type));
    let adapter = match name_filter {
        Some(filter) => {
            let needle = filter.to_lowercase();
            let position = adapters
                .iter()
                .position(|a| a.get_info().name.to_lowercase().contains(&needle));
            match position {
                Some(i) => adapters.swap_remove(i),
                None => {
                    return Err(DeviceError::NoMatchingAdapter {
                        requested: filter.to_owned(),
                        available: adapters.iter().map(|a| a.get_info().name).collect(),
                    });
                }
            }
        }
        None => adapters.swap_remove(0),
    };
    let summary = AdapterSummary::from_info(&adapter.get_info());
    let available = adapter.features();
    let required = wanted & available;
    let descriptor = wgpu::DeviceDescriptor {
        label: Some("framelab"),
        required_features: required,
        // The adapter's own limits: captures routinely exceed WebGPU's defaults (4096^2 shadow
        // arrays, 64^3 volumes), and the validator already checks against what is requested.
        required_limits: adapter.limits(),
        experimental_features: wgpu::ExperimentalFeatures::disabled(),
        memory_hints: wgpu::MemoryHints::Performance,
        trace: wgpu::Trace::Off,
    };
    let (device, queue) =
        pollster::block_on(adapter.request_device(&descriptor)).map_err(|source| {
            DeviceError::RequestDevice {
                adapter: summary.name.clone(),
                source,
            }
        })?;
    let faults = Faults::default();
    let uncaptured = faults.uncaptured.clone();
    device.on_uncaptured_error(std::sync::Arc::new(move |e: wgpu::Error| {
        if let Ok(mut v) = uncaptured.lock() {
            v.push(e.to_string());
        }
    }));
    let lost = faults.lost.clone();
    device.set_device_lost_callback(move |reason, message| {
        if let Ok(mut l) = lost.lock() {
            *l = Some(format!("{reason:?}: {message}"));
        }
    });
    Ok(GpuContext {
        instance,
        adapter,
        device,
        queue,
        summary,
        missing_features: wanted - available,
        faults,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hardware_is_preferred_over_software() {
        assert!(preference(wgpu::DeviceType::DiscreteGpu) < preference(wgpu::DeviceType::Cpu));
        assert!(preference(wgpu::DeviceType::IntegratedGpu) < preference(wgpu::DeviceType::Cpu));
    }

    #[test]
    fn summary_display_names_backend_and_type() {
        let s = AdapterSummary {
            name: "llvmpipe (LLVM 15.0.6, 256 bits)".into(),
            backend: "vulkan".into(),
            device_type: wgpu::DeviceType::Cpu,
            driver: "llvmpipe".into(),
            driver_info: "Mesa 22.3.6".into(),
        };
        assert_eq!(
            s.to_string(),
            "llvmpipe (LLVM 15.0.6, 256 bits) (vulkan, software (CPU), llvmpipe Mesa 22.3.6)"
        );
    }
}
