//! Every WGSL shader parses and validates with naga, without any GPU, and
//! every stage's vertex inputs match its Rust mirror's attributes (its
//! `StageDesc::vertex`); no varying uses `@interpolate(linear)`.

use naga::{Binding, Interpolation, ScalarKind, ShaderStage, TypeInner, VectorSize};
use zoovr::gpu::layer::LAYER_STAGE;
use zoovr::gpu::stage::stage_source;
use zoovr::gpu::StageDesc;
use zoovr::render::modes::iso;
use zoovr::render::modes::preint_tables::TABLE_BUILD;
use zoovr::render::modes::SHADERS;
use zoovr::render::Mode;

/// Every stage: the modes' and the layer stage.
fn stages() -> Vec<&'static StageDesc> {
    let mut v: Vec<&'static StageDesc> = Mode::ALL.iter().filter_map(|m| m.info().stage).collect();
    v.push(&LAYER_STAGE);
    // The isosurface stages over each volume.
    v.extend([
        &iso::ISO_EXACT_FRAG_STAGE,
        &iso::ISO_PREINT3D_STAGE,
        &iso::ISO_PREINT2D_STAGE,
        &iso::ISO_PREINT2D_CYL_STAGE,
        // The table modes' whole-piece quads.
        &zoovr::render::modes::preint_quads::PREINT3D_QUAD_STAGE,
        &zoovr::render::modes::preint_quads::PREINT2D_QUAD_STAGE,
        &zoovr::render::modes::preint_quads::PREINT2D_CYL_QUAD_STAGE,
    ]);
    // Every variant of the stages that integrate: by segment thickness and
    // Gauss rule (exact-frag's whole-piece quads only here).
    for stages in [
        &zoovr::render::modes::exact_frag::EXACT_FRAG_STAGES,
        &zoovr::render::modes::piece_quad::PIECE_QUAD_STAGES,
        &iso::ISO_EXACT_FRAG_STAGES,
    ] {
        v.extend(stages.all());
    }
    v.sort_by_key(|s| s.name);
    v.dedup_by_key(|s| s.name);
    v
}

fn parse(name: &str, src: &str) -> naga::Module {
    naga::front::wgsl::parse_str(src)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(src)))
}

#[test]
fn shaders_parse_and_validate() {
    // Every file in shaders/ is listed in SHADERS (and so included in the binary).
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".wgsl"))
        .collect();
    on_disk.sort();
    let mut listed: Vec<String> = SHADERS.iter().map(|(n, _)| n.to_string()).collect();
    listed.sort();
    assert_eq!(on_disk, listed);

    // Programs: every stage and compute kernel, as compiled (behind
    // shaders/common.wgsl). A file that is part of a program (concatenated
    // behind shared files) is validated in it; every other file alone.
    let mut programs: Vec<(&str, String)> = stages()
        .iter()
        .map(|s| (s.name, stage_source(s.wgsl)))
        .collect();
    programs.push((TABLE_BUILD.name, stage_source(TABLE_BUILD.wgsl)));
    for (name, src) in SHADERS {
        assert_eq!(
            *src,
            std::fs::read_to_string(dir.join(name)).unwrap(),
            "{name} differs from the embedded copy"
        );
        let in_program = programs.iter().any(|(_, p)| p.contains(src));
        if *name == "common.wgsl" {
            validate(name, src);
        } else if !in_program {
            validate(name, &stage_source(src));
        }
    }
    for (name, full) in &programs {
        validate(name, full);
    }
}

fn validate(name: &str, full: &str) {
    let module = parse(name, full);
    let mut validator = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    );
    if let Err(e) = validator.validate(&module) {
        panic!("{name}: {}", e.emit_to_string(full));
    }
}

/// wgpu vertex format of a naga scalar/vector type.
fn format_of(inner: &TypeInner) -> Option<wgpu::VertexFormat> {
    match inner {
        TypeInner::Scalar(s) if s.kind == ScalarKind::Float && s.width == 4 => {
            Some(wgpu::VertexFormat::Float32)
        }
        TypeInner::Scalar(s) if s.kind == ScalarKind::Uint && s.width == 4 => {
            Some(wgpu::VertexFormat::Uint32)
        }
        TypeInner::Vector { size, scalar } if scalar.kind == ScalarKind::Float => {
            Some(match size {
                VectorSize::Bi => wgpu::VertexFormat::Float32x2,
                VectorSize::Tri => wgpu::VertexFormat::Float32x3,
                VectorSize::Quad => wgpu::VertexFormat::Float32x4,
            })
        }
        TypeInner::Vector { size, scalar } if scalar.kind == ScalarKind::Uint => Some(match size {
            VectorSize::Bi => wgpu::VertexFormat::Uint32x2,
            VectorSize::Tri => wgpu::VertexFormat::Uint32x3,
            VectorSize::Quad => wgpu::VertexFormat::Uint32x4,
        }),
        _ => None,
    }
}

#[test]
fn vertex_inputs_match_rust_layout() {
    for stage in stages() {
        check_stage(stage);
    }
}

fn check_stage(stage: &StageDesc) {
    let name = stage.name;
    let module = parse(name, &stage_source(stage.wgsl));
    let vs = module
        .entry_points
        .iter()
        .find(|e| e.stage == ShaderStage::Vertex)
        .expect("vertex entry point");
    let mut inputs = Vec::new();
    for arg in &vs.function.arguments {
        match &module.types[arg.ty].inner {
            TypeInner::Struct { members, .. } => {
                for m in members {
                    if let Some(Binding::Location { location, .. }) = m.binding {
                        inputs.push((location, format_of(&module.types[m.ty].inner)));
                    }
                }
            }
            inner => {
                if let Some(Binding::Location { location, .. }) = arg.binding {
                    inputs.push((location, format_of(inner)));
                }
            }
        }
    }
    inputs.sort_by_key(|x| x.0);
    let rust: Vec<_> = stage
        .vertex
        .attributes
        .iter()
        .map(|a| (a.shader_location, Some(a.format)))
        .collect();
    assert_eq!(inputs, rust, "{name}");

    // Varyings: perspective-correct (the Mesa NaN pitfall of `linear`).
    for ep in &module.entry_points {
        if ep.stage != ShaderStage::Fragment {
            continue;
        }
        for arg in &ep.function.arguments {
            if let TypeInner::Struct { members, .. } = &module.types[arg.ty].inner {
                for m in members {
                    if let Some(Binding::Location { interpolation, .. }) = m.binding {
                        // Integers (the piece number) are flat; other
                        // varyings perspective-correct, or flat where
                        // constant over a triangle (the layer's colour).
                        match module.types[m.ty].inner {
                            TypeInner::Scalar(s) if s.kind == ScalarKind::Uint => {
                                assert_eq!(interpolation, Some(Interpolation::Flat), "{name}")
                            }
                            _ => assert!(
                                matches!(
                                    interpolation,
                                    Some(Interpolation::Perspective | Interpolation::Flat)
                                ),
                                "{name}: {interpolation:?}"
                            ),
                        }
                    }
                }
            }
        }
    }
}
