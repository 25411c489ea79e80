//! The GPU context: instance, adapter, device and queue, created headless.

use crate::error::{Error, Result};
use std::sync::{Arc, Mutex};

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
}

impl GpuContext {
    /// Creates a headless context on the adapter wgpu prefers (hardware first; Mesa's
    /// software Vulkan driver lavapipe where there is no GPU). The usual wgpu environment
    /// variables apply (`WGPU_BACKEND`, `WGPU_ADAPTER_NAME`, `WGPU_POWER_PREF`). Requests
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
        Ok(GpuContext {
            adapter,
            device,
            queue,
            info,
            lost,
        })
    }

    /// Wraps a host engine's adapter, device and queue. The host keeps its own device-lost
    /// callback (wgpu allows one): a loss then surfaces as [`Error::Gpu`] from the first
    /// operation wgpu refuses rather than as [`Error::DeviceLost`].
    pub fn from_parts(adapter: wgpu::Adapter, device: wgpu::Device, queue: wgpu::Queue) -> Self {
        let info = adapter.get_info();
        GpuContext {
            adapter,
            device,
            queue,
            info,
            lost: Arc::new(Mutex::new(None)),
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

    /// Runs `f`, turning any wgpu validation or out-of-memory error it raises into
    /// [`Error::Gpu`] instead of wgpu's default panic; [`Error::DeviceLost`] when the device
    /// has been reported lost (before or while `f` runs).
    pub fn checked<T>(&self, context: &str, f: impl FnOnce() -> T) -> Result<T> {
        self.check_lost(context)?;
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let value = f();
        let errors = [
            pollster::block_on(validation.pop()),
            pollster::block_on(oom.pop()),
        ];
        self.check_lost(context)?;
        match errors.into_iter().flatten().next() {
            Some(e) => Err(Error::Gpu {
                context: context.to_string(),
                message: e.to_string(),
            }),
            None => Ok(value),
        }
    }

    /// Waits for the queue to finish; [`Error::DeviceLost`] when the device was lost.
    pub fn wait(&self, context: &str) -> Result<()> {
        self.check_lost(context)?;
        let polled = self
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| Error::Gpu {
                context: context.to_string(),
                message: e.to_string(),
            });
        self.check_lost(context)?;
        polled
    }
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
