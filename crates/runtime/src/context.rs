//! The GPU context: instance, adapter, device and queue, created headless.

use crate::error::{Error, Result};
use std::sync::{Arc, Mutex};

/// The longest [`GpuContext::wait`] waits for the queue before it reports the device as
/// hung: 10 minutes, far above the slowest submission of the test suite on a software
/// rasteriser (a diffraction scene on llvmpipe through GL).
pub const WAIT_LIMIT: std::time::Duration = std::time::Duration::from_secs(600);

/// A wgpu device and queue with the adapter they came from. A host engine that has its own
/// device builds one with [`GpuContext::from_parts`].
///
/// # A lost device
///
/// A device can be lost at any time (driver reset, GPU removed, `wgpu::Device::destroy`).
/// Every call of the runtime then returns an error instead of panicking:
/// [`Error::DeviceLost`] once wgpu has reported the loss (a context from
/// [`GpuContext::new_headless`] registers a device-lost callback), and before that
/// [`Error::Gpu`] from the first operation wgpu refuses (every resource creation runs inside
/// [`GpuContext::checked`]'s error scopes). Buffers with initial contents are created through
/// [`BufferInitExt`], which returns an invalid buffer (reported by the next use) where
/// wgpu's own `DeviceExt::create_buffer_init` would panic; `clippy.toml` forbids the latter.
///
/// # wgpu errors
///
/// wgpu's default handler for an error raised outside an error scope panics. A context from
/// [`GpuContext::new_headless`] installs its own: the first such error is kept and returned
/// by the next [`GpuContext::checked`] or [`GpuContext::wait`] ([`Error::Gpu`], or
/// [`Error::OutOfMemory`]), so that work recorded between two checks (a render pass, a
/// submission) fails with an error naming the check that found it.
pub struct GpuContext {
    /// The adapter.
    pub adapter: wgpu::Adapter,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// Adapter name, driver and backend.
    pub info: wgpu::AdapterInfo,
    /// wgpu's reason and message once the device-lost callback has run.
    lost: Arc<Mutex<Option<String>>>,
    /// The first error wgpu raised outside an error scope, not yet reported.
    uncaptured: Arc<Mutex<Option<wgpu::Error>>>,
    /// A failure to inject into the next [`GpuContext::checked`] ([`GpuContext::inject_fault`]).
    fault: Mutex<Option<Fault>>,
}

/// A failure [`GpuContext::inject_fault`] makes wgpu raise, to test the error paths of a
/// program built on the runtime (the `nacre` binary's `NACRE_TEST_GPU_FAULT`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// A shader module whose WGSL does not parse (label [`Fault::SHADER_LABEL`]).
    BrokenShader,
    /// A 2-D texture one texel wider and taller than the device allows (label
    /// [`Fault::TEXTURE_LABEL`]).
    ImpossibleTexture,
}

impl Fault {
    /// The label of [`Fault::BrokenShader`]'s module.
    pub const SHADER_LABEL: &'static str = "injected broken shader";
    /// The label of [`Fault::ImpossibleTexture`]'s texture.
    pub const TEXTURE_LABEL: &'static str = "injected impossible texture";

    /// The fault named `name` (`broken-shader`, `impossible-texture`).
    pub fn from_name(name: &str) -> Option<Fault> {
        match name {
            "broken-shader" => Some(Fault::BrokenShader),
            "impossible-texture" => Some(Fault::ImpossibleTexture),
            _ => None,
        }
    }

    /// Raises the fault on `device` (inside the caller's error scopes).
    fn raise(self, device: &wgpu::Device) {
        match self {
            Fault::BrokenShader => {
                drop(device.create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(Fault::SHADER_LABEL),
                    source: wgpu::ShaderSource::Wgsl("fn broken( -> f32 { return 1.0 }".into()),
                }));
            }
            Fault::ImpossibleTexture => {
                let side = device.limits().max_texture_dimension_2d.saturating_add(1);
                drop(device.create_texture(&wgpu::TextureDescriptor {
                    label: Some(Fault::TEXTURE_LABEL),
                    size: wgpu::Extent3d {
                        width: side,
                        height: side,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: wgpu::TextureFormat::Rgba8Unorm,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING,
                    view_formats: &[],
                }));
            }
        }
    }
}

impl GpuContext {
    /// Creates a headless context on the adapter wgpu prefers (hardware first; Mesa's
    /// software Vulkan driver lavapipe where there is no GPU). The usual wgpu environment
    /// variables apply (`WGPU_BACKEND`, `WGPU_ADAPTER_NAME`, `WGPU_POWER_PREF`):
    /// `WGPU_BACKEND=vulkan` or `WGPU_BACKEND=gl` (OpenGL ES through EGL, e.g. Mesa's
    /// llvmpipe) selects the backend. Requests
    /// timestamp queries where the adapter has them, and the adapter's own limits.
    pub fn new_headless() -> Result<Self> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        // WGPU_ADAPTER_NAME is matched here rather than by wgpu's helper, which panics when
        // no adapter matches.
        let adapter = match std::env::var("WGPU_ADAPTER_NAME") {
            Ok(wanted) => {
                let adapters =
                    pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
                let names: Vec<String> = adapters.iter().map(|a| a.get_info().name).collect();
                adapters
                    .into_iter()
                    .find(|a| {
                        a.get_info()
                            .name
                            .to_lowercase()
                            .contains(&wanted.to_lowercase())
                    })
                    .ok_or_else(|| {
                        Error::NoAdapter(format!(
                            "WGPU_ADAPTER_NAME={wanted} matches none of the adapters found: {names:?}"
                        ))
                    })?
            }
            Err(_) => pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(
                &instance, None,
            ))
            .map_err(|e| Error::NoAdapter(e.to_string()))?,
        };
        let info = adapter.get_info();
        let features = adapter.features() & wgpu::Features::TIMESTAMP_QUERY;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("nacre"),
            required_features: features,
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| Error::Device {
            adapter: info.name.clone(),
            message: e.to_string(),
        })?;
        let lost = Arc::new(Mutex::new(None));
        let flag = Arc::clone(&lost);
        device.set_device_lost_callback(move |reason, message| {
            let text = if message.is_empty() {
                format!("{reason:?}")
            } else {
                format!("{reason:?}: {message}")
            };
            *flag.lock().unwrap_or_else(|e| e.into_inner()) = Some(text);
        });
        let uncaptured = Arc::new(Mutex::new(None));
        let first = Arc::clone(&uncaptured);
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            first
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .get_or_insert(error);
        }));
        Ok(GpuContext {
            adapter,
            device,
            queue,
            info,
            lost,
            uncaptured,
            fault: Mutex::new(None),
        })
    }

    /// Wraps a host engine's adapter, device and queue. The host keeps its own device-lost
    /// callback and uncaptured-error handler (wgpu allows one of each): a loss then surfaces
    /// as [`Error::Gpu`] from the first operation wgpu refuses rather than as
    /// [`Error::DeviceLost`], and errors outside the runtime's error scopes go to the host's
    /// handler.
    pub fn from_parts(adapter: wgpu::Adapter, device: wgpu::Device, queue: wgpu::Queue) -> Self {
        let info = adapter.get_info();
        GpuContext {
            adapter,
            device,
            queue,
            info,
            lost: Arc::new(Mutex::new(None)),
            uncaptured: Arc::new(Mutex::new(None)),
            fault: Mutex::new(None),
        }
    }

    /// Makes the next [`GpuContext::checked`] raise `fault` inside its error scopes, so that
    /// it fails with the error wgpu reports for it (a test hook: the error paths of a whole
    /// program, up to its message and exit status, without a faulty driver).
    pub fn inject_fault(&self, fault: Fault) {
        *self.fault.lock().unwrap_or_else(|e| e.into_inner()) = Some(fault);
    }

    /// The error wgpu raised outside any error scope since the last check, as the error of
    /// `context`.
    fn check_uncaptured(&self, context: &str) -> Result<()> {
        let taken = self
            .uncaptured
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take();
        match taken {
            Some(e) => Err(self.gpu_error(context, &e)),
            None => Ok(()),
        }
    }

    /// The runtime's error for wgpu's `error` raised while `context`.
    fn gpu_error(&self, context: &str, error: &wgpu::Error) -> Error {
        match error {
            wgpu::Error::OutOfMemory { .. } => Error::OutOfMemory {
                adapter: self.info.name.clone(),
                context: context.to_string(),
            },
            other => Error::Gpu {
                context: context.to_string(),
                message: one_line(&other.to_string()),
            },
        }
    }

    /// wgpu's reason once the device has been reported lost; `None` while it is usable.
    pub fn lost_reason(&self) -> Option<String> {
        self.lost.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }

    /// [`Error::DeviceLost`] when the device has been reported lost.
    fn check_lost(&self, context: &str) -> Result<()> {
        match self.lost_reason() {
            Some(reason) => Err(Error::DeviceLost {
                adapter: self.info.name.clone(),
                context: context.to_string(),
                reason,
            }),
            None => Ok(()),
        }
    }

    /// One line naming the adapter, its type, driver and backend.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {:?} backend, driver {} {})",
            self.info.name,
            self.info.device_type,
            self.info.backend,
            self.info.driver,
            self.info.driver_info
        )
    }

    /// Runs `f`, turning any wgpu validation, internal or out-of-memory error it raises
    /// into [`Error::Gpu`] or [`Error::OutOfMemory`] instead of wgpu's default panic;
    /// [`Error::DeviceLost`] when the device has been reported lost (before or while `f`
    /// runs). An error wgpu raised outside any scope since the last check is returned first.
    pub fn checked<T>(&self, context: &str, f: impl FnOnce() -> T) -> Result<T> {
        self.check_lost(context)?;
        self.check_uncaptured(context)?;
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let internal = self.device.push_error_scope(wgpu::ErrorFilter::Internal);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let fault = self.fault.lock().unwrap_or_else(|e| e.into_inner()).take();
        if let Some(fault) = fault {
            fault.raise(&self.device);
        }
        let value = f();
        let errors = [
            pollster::block_on(validation.pop()),
            pollster::block_on(internal.pop()),
            pollster::block_on(oom.pop()),
        ];
        self.check_lost(context)?;
        match errors.into_iter().flatten().next() {
            Some(e) => Err(self.gpu_error(context, &e)),
            None => Ok(value),
        }
    }

    /// Waits for the queue to finish; [`Error::DeviceLost`] when the device was lost, and
    /// the error wgpu raised outside any scope since the last check ([`Error::Gpu`],
    /// [`Error::OutOfMemory`]).
    ///
    /// An "indefinite" wait is not one on every backend: wgpu's GL backend waits on a GL
    /// fence with `glClientWaitSync`, whose timeout is a signed 32-bit count of nanoseconds,
    /// so each wait gives up after 2.1 s (wgpu-hal `gles::Fence::wait`) and the poll
    /// reports [`wgpu::PollError::Timeout`] while the GPU is still working — a long
    /// dispatch on llvmpipe (a diffraction scene) takes longer. The wait therefore polls
    /// again after a timeout until the work is done, and reports [`Error::Gpu`] only when
    /// the queue has not finished within [`WAIT_LIMIT`] in all (a hung device).
    pub fn wait(&self, context: &str) -> Result<()> {
        self.check_lost(context)?;
        self.check_uncaptured(context)?;
        let start = std::time::Instant::now();
        let polled = loop {
            match self.device.poll(wgpu::PollType::wait_indefinitely()) {
                Ok(_) => break Ok(()),
                // A device lost meanwhile ends the wait at once.
                Err(wgpu::PollError::Timeout) if start.elapsed() < WAIT_LIMIT => {
                    self.check_lost(context)?
                }
                Err(wgpu::PollError::Timeout) => {
                    break Err(Error::Gpu {
                        context: context.to_string(),
                        message: format!(
                            "the queue did not finish within {} s (a hung device?)",
                            WAIT_LIMIT.as_secs()
                        ),
                    });
                }
                Err(e) => {
                    break Err(Error::Gpu {
                        context: context.to_string(),
                        message: e.to_string(),
                    });
                }
            }
        };
        self.check_lost(context)?;
        self.check_uncaptured(context)?;
        polled
    }
}

/// wgpu's multi-line report (`Validation Error`, `Caused by:`, the operation with its label,
/// the cause) as one line: its other lines trimmed and joined by `: `.
fn one_line(report: &str) -> String {
    report
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && *l != "Caused by:" && *l != "Validation Error")
        .map(|l| l.trim_end_matches(':'))
        .collect::<Vec<_>>()
        .join(": ")
}

/// `create_buffer_init` that does not panic on a lost device: the drop-in replacement for
/// `wgpu::util::DeviceExt::create_buffer_init` used throughout the runtime.
pub trait BufferInitExt {
    /// A buffer of `desc.usage` holding `desc.contents` (padded to
    /// `wgpu::COPY_BUFFER_ALIGNMENT`, at least one alignment unit). Where the device cannot
    /// map the new buffer (it was lost), returns that buffer unwritten: wgpu reports the
    /// invalid buffer at its first use, which [`GpuContext::checked`] turns into an error.
    fn create_buffer_init(&self, desc: &wgpu::util::BufferInitDescriptor<'_>) -> wgpu::Buffer;
}

impl BufferInitExt for wgpu::Device {
    fn create_buffer_init(&self, desc: &wgpu::util::BufferInitDescriptor<'_>) -> wgpu::Buffer {
        let align = wgpu::COPY_BUFFER_ALIGNMENT;
        let size = (desc.contents.len() as u64).div_ceil(align).max(1) * align;
        let buffer = self.create_buffer(&wgpu::BufferDescriptor {
            label: desc.label,
            size,
            usage: desc.usage,
            mapped_at_creation: true,
        });
        if let Ok(mut view) = buffer.get_mapped_range_mut(..) {
            view.slice(..desc.contents.len())
                .copy_from_slice(desc.contents);
            drop(view);
            buffer.unmap();
        }
        buffer
    }
}
