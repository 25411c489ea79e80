//! The GPU context of the commands that use one (`render`, `bench-gpu`, the probes), the
//! backend choice and the test hook that injects a wgpu failure.

use crate::error::Result;
use nacre_runtime::{Fault, GpuContext};

/// The top-level help's note on GPUs and exit statuses.
pub const HELP: &str = "\
GPU: the commands that render or probe run on the adapter wgpu picks (hardware first; Mesa's
lavapipe or llvmpipe without a GPU). WGPU_BACKEND=vulkan or WGPU_BACKEND=gl selects the
backend, WGPU_ADAPTER_NAME an adapter by name.

Exit status: 0 success; 2 bad input or a failed command (one line on stderr, no output file
written); 3 no usable GPU (no adapter, or the adapter refused to create a device).";

/// The environment variable naming a [`Fault`] to inject into the first GPU operation (a
/// test hook: `broken-shader` or `impossible-texture`).
pub const FAULT_VAR: &str = "NACRE_TEST_GPU_FAULT";

/// Mesa's switch for the extensions a GL driver lists.
const MESA_EXTENSION_OVERRIDE: &str = "MESA_EXTENSION_OVERRIDE";

/// Lets wgpu's GL backend render into 32-bit float targets on Mesa (the linear output and the
/// probes). RGBA32F is colour-renderable in every desktop OpenGL from 3.0 (one of the
/// specification's required framebuffer formats), but wgpu 30 believes it only when the driver
/// lists `GL_ARB_color_buffer_float` or `GL_EXT_color_buffer_float`, and Mesa's core
/// profile (llvmpipe) lists neither: the extension is listed with Mesa's own switch, unless
/// the user set it. Other drivers ignore the variable; where a float target is refused,
/// the render fails with the runtime's error naming the format.
///
/// Called first thing in `main`, before any other thread exists.
pub fn list_float_targets_on_mesa_gl() {
    if std::env::var_os(MESA_EXTENSION_OVERRIDE).is_none() {
        // SAFETY: called first thing in `main`, before any other thread exists.
        unsafe { std::env::set_var(MESA_EXTENSION_OVERRIDE, "+GL_ARB_color_buffer_float") };
    }
}

/// A headless context on wgpu's adapter (`WGPU_BACKEND`, `WGPU_ADAPTER_NAME` apply), with
/// the fault of [`FAULT_VAR`] armed when it is set.
pub fn context() -> Result<GpuContext> {
    let ctx = GpuContext::new_headless()?;
    if let Some(fault) = std::env::var(FAULT_VAR)
        .ok()
        .as_deref()
        .and_then(Fault::from_name)
    {
        ctx.inject_fault(fault);
    }
    Ok(ctx)
}
