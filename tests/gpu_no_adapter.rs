//! With `WGPU_BACKEND` naming a backend this platform lacks, opening the GPU
//! fails with `GpuError::NoAdapter`, whose message names the apt packages,
//! instead of panicking. (Own test binary: it sets a process-wide variable.)

use zoovr::gpu::{Context, GpuError, GpuOptions};

#[test]
fn missing_backend_is_a_clear_error() {
    let absent = if cfg!(target_os = "windows") {
        "metal"
    } else {
        "dx12"
    };
    std::env::set_var("WGPU_BACKEND", absent);
    match Context::new(&GpuOptions::default()) {
        Err(e @ GpuError::NoAdapter { .. }) => {
            let msg = e.to_string();
            assert!(msg.contains("mesa-vulkan-drivers"), "{msg}");
            assert!(msg.contains("libgl1-mesa-dri"), "{msg}");
        }
        Err(e) => panic!("unexpected error: {e}"),
        Ok(ctx) => panic!("got an adapter for {absent}: {}", ctx.info()),
    }
    // An explicit backend overrides the variable.
    std::env::set_var("WGPU_BACKEND", absent);
    let r = Context::new(&GpuOptions {
        backend: Some(zoovr::gpu::Backend::Vulkan),
        cpu_adapter: false,
    });
    assert!(!matches!(r, Err(GpuError::UnknownBackend(_))));
    if let Err(e) = r {
        eprintln!("vulkan unavailable here: {e}");
    }
    assert!("opengl".parse::<zoovr::gpu::Backend>().is_ok());
    assert!(matches!(
        "metal".parse::<zoovr::gpu::Backend>(),
        Err(GpuError::UnknownBackend(_))
    ));
}
