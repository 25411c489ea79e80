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
