//! The headless Bevy app the examples and tests share: Bevy's default plugins without a
//! window (and, built with the `viewer` feature, without winit's event loop, which needs a
//! display), without pipelined rendering, with [`NacrePlugin`], plugins finished.
#![allow(dead_code)]

use bevy::app::PluginsState;
use bevy::prelude::*;
use bevy::render::RenderPlugin;
use bevy::render::pipelined_rendering::PipelinedRenderingPlugin;
use bevy::window::ExitCondition;
use bevy_nacre::NacrePlugin;
use std::path::Path;

/// A headless app reading assets under `asset_root`, rendering with `render` (e.g.
/// `synchronous_pipeline_compilation`, so that the first frames that need a pipeline draw
/// with it rather than skip the material while it compiles).
pub fn headless_app(asset_root: &Path, render: RenderPlugin) -> App {
    let mut app = App::new();
    let plugins = DefaultPlugins
        .set(WindowPlugin {
            primary_window: None,
            exit_condition: ExitCondition::DontExit,
            close_when_requested: false,
            ..default()
        })
        .set(AssetPlugin {
            file_path: asset_root.to_string_lossy().into_owned(),
            ..default()
        })
        .set(render)
        .disable::<PipelinedRenderingPlugin>();
    // Built with the `viewer` feature (as test.sh builds everything), Bevy's default plugins
    // would open winit's event loop, which needs a display: not here.
    #[cfg(feature = "viewer")]
    let plugins = plugins.disable::<bevy::winit::WinitPlugin>();
    app.add_plugins(plugins).add_plugins(NacrePlugin);
    while app.plugins_state() == PluginsState::Adding {
        bevy::tasks::tick_global_task_pools_on_main_thread();
    }
    app.finish();
    app.cleanup();
    app
}
