//! A lost device (issue 9): after `wgpu::Device::destroy` — what a driver reset or a removed
//! GPU looks like to wgpu — loading tables, rendering and probing return errors, never panic.
//! Each test owns its device (it destroys it). A missing adapter fails these tests: they never
//! skip.

use nacre_runtime::bindings::{TechniqueBinding, TechniqueOptions};
use nacre_runtime::params::FilmInput;
use nacre_runtime::probe::run_probe;
use nacre_runtime::render::{SceneKind, SceneOptions, render_scene};
use nacre_runtime::{Error, GpuContext, TableSet, Technique};

mod support;
use support::manifest;

fn fresh_context() -> GpuContext {
    GpuContext::new_headless().unwrap_or_else(|e| {
        panic!("the lost-device tests need an adapter (CI installs mesa-vulkan-drivers): {e}")
    })
}

fn small_sphere() -> SceneOptions {
    let mut options = SceneOptions::new(SceneKind::Sphere);
    options.width = 32;
    options.height = 24;
    options
}

fn assert_lost<T>(result: Result<T, Error>, what: &str) {
    match result {
        Err(e @ Error::DeviceLost { .. }) => {
            let text = e.to_string();
            assert!(text.contains("lost"), "{what}: {text}");
        }
        Err(other) => panic!("{what}: expected Error::DeviceLost, got {other:?}"),
        Ok(_) => panic!("{what}: succeeded on a lost device"),
    }
}

#[test]
fn a_device_lost_after_loading_fails_rendering_and_probing_with_an_error() {
    let ctx = fresh_context();
    let mut tables = TableSet::load(&ctx, &manifest("film-dielectric")).unwrap();
    tables.add(&ctx, &manifest("fourier-srgb")).unwrap();
    // The same work succeeds before the loss (so the errors below are the loss's).
    render_scene(&ctx, &tables, Technique::Lut, &small_sphere()).unwrap();
    let binding = TechniqueBinding::new(
        &ctx,
        &tables,
        Technique::Lut,
        &TechniqueOptions::default(),
        &tables.colorimeter().unwrap(),
    )
    .unwrap();
    let inputs = vec![FilmInput::default(); 8];
    run_probe(&ctx, &binding, &inputs).unwrap();

    ctx.device.destroy();
    assert_lost(ctx.wait("waiting after the loss"), "wait");
    assert!(ctx.lost_reason().is_some());
    for technique in [Technique::Lut, Technique::Fourier] {
        assert_lost(
            render_scene(&ctx, &tables, technique, &small_sphere()),
            "render_scene",
        );
    }
    assert_lost(run_probe(&ctx, &binding, &inputs), "run_probe");
    assert_lost(
        TableSet::load(&ctx, &manifest("soap-film")),
        "TableSet::load",
    );
}

#[test]
fn work_issued_right_after_the_loss_is_an_error_not_a_panic() {
    // No wait between the loss and the next call: wgpu may not have run the device-lost
    // callback yet, so the error can be the first refused operation's (Error::Gpu).
    let ctx = fresh_context();
    ctx.device.destroy();
    let loaded = TableSet::load(&ctx, &manifest("film-dielectric"));
    assert!(
        matches!(loaded, Err(Error::Gpu { .. } | Error::DeviceLost { .. })),
        "TableSet::load: {:?}",
        loaded.as_ref().err()
    );
    let ctx = fresh_context();
    let tables = TableSet::load(&ctx, &manifest("film-dielectric")).unwrap();
    ctx.device.destroy();
    let rendered = render_scene(&ctx, &tables, Technique::Lut, &small_sphere());
    assert!(
        matches!(rendered, Err(Error::Gpu { .. } | Error::DeviceLost { .. })),
        "render_scene: {:?}",
        rendered.as_ref().err()
    );
}
