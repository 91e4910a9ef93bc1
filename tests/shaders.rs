//! Every WGSL source (with its generated prelude) parses and validates with naga; every GPU struct
//! has the same size, field offsets and scalars in WGSL as in Rust; and every pass's binding table
//! agrees with the `@group(0) @binding(n)` globals its shader's entry points use: name, kind,
//! texture type, buffer size or element stride, access, and the stages that read it. No GPU needed.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use naga::valid::{Capabilities, ModuleInfo, ValidationFlags, Validator};
use naga::{
    AddressSpace, ArraySize, ImageClass, ImageDimension, Module, ScalarKind, StorageAccess, TypeInner,
};
use terramp::gpu::bindings::{Binding, BindingKind, PipelineBindings};
use terramp::gpu::gpu_types::layouts;
use terramp::gpu::shaders::WgslSource;
use terramp::gpu::struct_layout::{ScalarKind as RustScalar, StructLayout};
use terramp::passes::{PIPELINE_BINDINGS, SHADERS};

fn parse(shader: &WgslSource) -> (Module, ModuleInfo) {
    let text = shader.source();
    let module = naga::front::wgsl::parse_str(&text)
        .unwrap_or_else(|e| panic!("{}.wgsl: {}", shader.name, e.emit_to_string(&text)));
    let info = Validator::new(ValidationFlags::all(), Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}.wgsl does not validate: {e:?}", shader.name));
    (module, info)
}

#[test]
fn every_shader_validates() {
    for shader in SHADERS {
        parse(shader);
    }
}

/// Every scalar of a WGSL type placed at `base`, in the Rust side's vocabulary.
fn wgsl_leaves(
    module: &Module,
    ty: naga::Handle<naga::Type>,
    base: usize,
    out: &mut Vec<(usize, RustScalar)>,
) {
    let scalar = |s: naga::Scalar| match (s.kind, s.width) {
        (ScalarKind::Float, 4) => RustScalar::F32,
        (ScalarKind::Uint, 4) => RustScalar::U32,
        (ScalarKind::Sint, 4) => RustScalar::I32,
        other => panic!("no Rust twin for a WGSL scalar {other:?}"),
    };
    match &module.types[ty].inner {
        TypeInner::Scalar(s) | TypeInner::Atomic(s) => out.push((base, scalar(*s))),
        TypeInner::Vector { size, scalar: s } => {
            out.extend((0..*size as usize).map(|i| (base + 4 * i, scalar(*s))));
        }
        TypeInner::Matrix { columns, rows, scalar: s } => {
            // Columns are aligned like vectors of their rows (vec3 columns take 16 bytes).
            let column_bytes = if *rows as usize == 2 { 8 } else { 16 };
            for c in 0..*columns as usize {
                out.extend((0..*rows as usize).map(|r| (base + c * column_bytes + 4 * r, scalar(*s))));
            }
        }
        TypeInner::Array { base: element, size: ArraySize::Constant(n), stride } => {
            for i in 0..n.get() as usize {
                wgsl_leaves(module, *element, base + i * *stride as usize, out);
            }
        }
        TypeInner::Struct { members, .. } => {
            for m in members {
                wgsl_leaves(module, m.ty, base + m.offset as usize, out);
            }
        }
        other => panic!("no Rust twin for a WGSL {other:?}"),
    }
}

/// Where `rust` and the WGSL struct of its name in `module` disagree, if they do.
fn struct_mismatch(module: &Module, rust: &StructLayout) -> Option<String> {
    let (handle, ty) = module.types.iter().find(|(_, t)| t.name.as_deref() == Some(rust.name))?;
    let TypeInner::Struct { members, span } = &ty.inner else {
        return Some(format!("{} is not a struct", rust.name));
    };
    if *span as usize != rust.size {
        return Some(format!("{}: {span} bytes in WGSL, {} in Rust", rust.name, rust.size));
    }
    let mut leaves = Vec::new();
    wgsl_leaves(module, handle, 0, &mut leaves);
    if leaves != rust.leaves {
        let first = leaves.iter().zip(&rust.leaves).position(|(a, b)| a != b).unwrap_or(leaves.len());
        return Some(format!(
            "{}: scalars differ from #{first}: WGSL {:?}, Rust {:?}",
            rust.name,
            leaves.get(first),
            rust.leaves.get(first)
        ));
    }
    // Same scalars everywhere; the named fields must also be the same, in the same order, at the
    // same offsets (padding may be split differently; a struct WGSL reads as an array of its
    // scalars, like `SeedCounters`, shares no name and is checked by its scalars alone).
    let named = |n: &&str| !n.starts_with('_');
    let wgsl_names: Vec<&str> = members.iter().filter_map(|m| m.name.as_deref()).filter(named).collect();
    let rust_names: Vec<&str> = rust.fields.iter().map(|f| f.name).filter(named).collect();
    if wgsl_names.iter().any(|n| rust_names.contains(n)) && wgsl_names != rust_names {
        return Some(format!("{}: fields {wgsl_names:?} in WGSL, {rust_names:?} in Rust", rust.name));
    }
    for m in members {
        let name = m.name.as_deref().unwrap_or_default();
        if let Some(field) = rust.fields.iter().find(|f| f.name == name)
            && field.offset != m.offset as usize
        {
            return Some(format!(
                "{}.{name}: offset {} in WGSL, {} in Rust",
                rust.name, m.offset, field.offset
            ));
        }
    }
    None
}

#[test]
fn gpu_structs_match_their_wgsl_twins_field_by_field() {
    let modules: Vec<(&str, Module)> = SHADERS.iter().map(|s| (s.name, parse(s).0)).collect();
    for rust in layouts() {
        let mut found = 0;
        for (shader, module) in &modules {
            if module.types.iter().any(|(_, t)| t.name.as_deref() == Some(rust.name)) {
                found += 1;
                if let Some(problem) = struct_mismatch(module, &rust) {
                    panic!("{shader}.wgsl: {problem}");
                }
            }
        }
        assert!(found > 0, "{} is in no shader", rust.name);
    }
}

/// Where one binding disagrees with the WGSL global it binds, if it does.
fn binding_mismatch(module: &Module, global: &naga::GlobalVariable, b: &Binding) -> Option<String> {
    let name = global.name.as_deref().unwrap_or_default();
    if name != b.name {
        return Some(format!("binding {} is `{name}` in WGSL, `{}` in Rust", b.binding, b.name));
    }
    let ty = &module.types[global.ty].inner;
    let size = |ty: naga::Handle<naga::Type>| module.types[ty].inner.size(module.to_ctx()) as u64;
    let dims = |d: wgpu::TextureViewDimension| match d {
        wgpu::TextureViewDimension::D2 => (ImageDimension::D2, false),
        wgpu::TextureViewDimension::D2Array => (ImageDimension::D2, true),
        wgpu::TextureViewDimension::D3 => (ImageDimension::D3, false),
        other => panic!("no view dimension {other:?} in any shader"),
    };
    let ok = match (b.kind, global.space, ty) {
        (BindingKind::Uniform { bytes }, AddressSpace::Uniform, _) => size(global.ty) == bytes,
        (BindingKind::Storage { read_only, bytes, runtime_array }, AddressSpace::Storage { access }, ty) => {
            let access_ok = access.contains(StorageAccess::STORE) != read_only;
            let size_ok = match ty {
                TypeInner::Array { size: ArraySize::Dynamic, stride, .. } => {
                    runtime_array && u64::from(*stride) == bytes
                }
                _ => !runtime_array && size(global.ty) == bytes,
            };
            access_ok && size_ok
        }
        (
            BindingKind::Texture { sample_type, dimension },
            AddressSpace::Handle,
            TypeInner::Image { dim, arrayed, class },
        ) => {
            let class_ok = match (sample_type, class) {
                (
                    wgpu::TextureSampleType::Float { .. },
                    ImageClass::Sampled { kind: ScalarKind::Float, multi },
                ) => !multi,
                (wgpu::TextureSampleType::Uint, ImageClass::Sampled { kind: ScalarKind::Uint, multi }) => {
                    !multi
                }
                (wgpu::TextureSampleType::Sint, ImageClass::Sampled { kind: ScalarKind::Sint, multi }) => {
                    !multi
                }
                (wgpu::TextureSampleType::Depth, ImageClass::Depth { multi }) => !multi,
                _ => false,
            };
            class_ok && dims(dimension) == (*dim, *arrayed)
        }
        (
            BindingKind::StorageTexture { format, dimension },
            AddressSpace::Handle,
            TypeInner::Image { dim, arrayed, class },
        ) => {
            use naga::StorageFormat as Naga;
            use wgpu::TextureFormat as Wgpu;
            let format_ok = matches!(
                (format, class),
                (Wgpu::R32Float, ImageClass::Storage { format: Naga::R32Float, .. })
                    | (Wgpu::Rgba32Float, ImageClass::Storage { format: Naga::Rgba32Float, .. })
                    | (Wgpu::Rgba16Float, ImageClass::Storage { format: Naga::Rgba16Float, .. })
            );
            format_ok && dims(dimension) == (*dim, *arrayed)
        }
        (BindingKind::Sampler(ty), AddressSpace::Handle, TypeInner::Sampler { comparison }) => {
            *comparison == (ty == wgpu::SamplerBindingType::Comparison)
        }
        _ => false,
    };
    (!ok).then(|| {
        format!(
            "binding {} `{name}`: Rust says {:?}, WGSL declares {:?} {ty:?}",
            b.binding, b.kind, global.space
        )
    })
}

/// Where a pipeline's binding table disagrees with its shader, if it does.
fn table_mismatch(p: &PipelineBindings) -> Option<String> {
    let (module, info) = parse(p.shader);
    let bound =
        |g: &naga::GlobalVariable| g.binding.as_ref().filter(|rb| rb.group == p.group).map(|rb| rb.binding);
    // Every table entry whose number the shader declares must describe that global.
    for b in p.bindings {
        let declared = module.global_variables.iter().find(|(_, g)| bound(g) == Some(b.binding));
        if let Some((_, global)) = declared
            && let Some(problem) = binding_mismatch(&module, global, b)
        {
            return Some(problem);
        }
    }
    // Every global the pipeline's entry points use must be in the table, visible to their stage.
    for name in p.entry_points {
        let Some(index) = module.entry_points.iter().position(|e| e.name == *name) else {
            return Some(format!("no entry point {name}"));
        };
        let stage = match module.entry_points[index].stage {
            naga::ShaderStage::Vertex => wgpu::ShaderStages::VERTEX,
            naga::ShaderStage::Fragment => wgpu::ShaderStages::FRAGMENT,
            _ => wgpu::ShaderStages::COMPUTE,
        };
        let uses = info.get_entry_point(index);
        for (handle, global) in module.global_variables.iter() {
            let Some(number) = bound(global) else { continue };
            if uses[handle].is_empty() {
                continue;
            }
            let global_name = global.name.as_deref().unwrap_or_default();
            match p.bindings.iter().find(|b| b.binding == number) {
                None => {
                    return Some(format!("{name} uses binding {number} `{global_name}`, not in the table"));
                }
                Some(b) if !b.visibility.contains(stage) => {
                    return Some(format!(
                        "{name} ({stage:?}) uses binding {number} `{global_name}`, visible to {:?}",
                        b.visibility
                    ));
                }
                Some(_) => {}
            }
        }
    }
    None
}

#[test]
fn binding_tables_match_the_globals_their_shaders_use() {
    for p in PIPELINE_BINDINGS {
        if let Some(problem) = table_mismatch(p) {
            panic!("{}.wgsl {:?}: {problem}", p.shader.name, p.entry_points);
        }
    }
    // Every shader is checked by some table.
    for shader in SHADERS {
        assert!(
            PIPELINE_BINDINGS.iter().any(|p| p.shader.name == shader.name),
            "{} has no table",
            shader.name
        );
    }
}

/// The checks catch a change made on one side only: a binding renumbered, retyped or resized in
/// Rust, a struct field moved or retyped.
#[test]
fn the_checks_fail_when_one_side_changes() {
    let tlm = PIPELINE_BINDINGS.iter().find(|p| p.shader.name == "tile_load_map").unwrap();
    let mut bindings = tlm.bindings.to_vec();
    // Renumbered: the spans at the ranges' number.
    bindings[1].binding = 2;
    let mut changed = *tlm;
    changed.bindings = Box::leak(bindings.into_boxed_slice());
    assert!(table_mismatch(&changed).is_some(), "a renumbered binding passed");
    // Resized: the spans' element one word longer.
    let mut bindings = tlm.bindings.to_vec();
    bindings[1].kind = BindingKind::Storage { read_only: true, bytes: 20, runtime_array: true };
    changed.bindings = Box::leak(bindings.into_boxed_slice());
    assert!(table_mismatch(&changed).is_some(), "a resized binding passed");
    // Dropped: a binding the shader uses missing from the table.
    changed.bindings = Box::leak(tlm.bindings[1..].to_vec().into_boxed_slice());
    assert!(table_mismatch(&changed).is_some(), "a missing binding passed");

    let module = parse(tlm.shader).0;
    let mut span = layouts().into_iter().find(|l| l.name == "TlmSpan").unwrap();
    assert_eq!(struct_mismatch(&module, &span), None);
    // Two fields swapped (same scalars, different offsets) and a field retyped.
    span.fields.swap(1, 2);
    let (a, b) = (span.fields[1].offset, span.fields[2].offset);
    (span.fields[1].offset, span.fields[2].offset) = (b, a);
    assert!(struct_mismatch(&module, &span).is_some(), "a moved field passed");
    let mut span = layouts().into_iter().find(|l| l.name == "TlmSpan").unwrap();
    span.leaves[2].1 = RustScalar::F32;
    assert!(struct_mismatch(&module, &span).is_some(), "a retyped field passed");
}

#[test]
fn vertex_attributes_match_the_vertex_stage_inputs() {
    use terramp::gpu::gpu_types::vertex_layouts;
    for (rust, shader, input) in vertex_layouts() {
        let shader = SHADERS.iter().find(|s| s.name == shader).unwrap();
        let module = parse(shader).0;
        let (_, ty) = module.types.iter().find(|(_, t)| t.name.as_deref() == Some(input)).unwrap();
        let TypeInner::Struct { members, .. } = &ty.inner else { panic!("{input} is not a struct") };
        let attributes = rust.vertex_attributes();
        assert_eq!(members.len(), attributes.len(), "{}: {input} has another number of inputs", rust.name);
        for (m, a) in members.iter().zip(&attributes) {
            let Some(naga::Binding::Location { location, .. }) = m.binding else {
                panic!("{input}: not an attribute")
            };
            assert_eq!(location, a.shader_location, "{}: {input}.{:?}", rust.name, m.name);
            let mut leaves = Vec::new();
            wgsl_leaves(&module, m.ty, 0, &mut leaves);
            let wgsl_format = match (leaves[0].1, leaves.len()) {
                (RustScalar::F32, 1) => wgpu::VertexFormat::Float32,
                (RustScalar::F32, 2) => wgpu::VertexFormat::Float32x2,
                (RustScalar::F32, 3) => wgpu::VertexFormat::Float32x3,
                (RustScalar::F32, 4) => wgpu::VertexFormat::Float32x4,
                (RustScalar::U32, 1) => wgpu::VertexFormat::Uint32,
                (RustScalar::U32, 2) => wgpu::VertexFormat::Uint32x2,
                (RustScalar::I32, 1) => wgpu::VertexFormat::Sint32,
                other => panic!("{input}.{:?}: {other:?}", m.name),
            };
            assert_eq!(wgsl_format, a.format, "{}: {input}.{:?}", rust.name, m.name);
        }
    }
}

#[test]
fn indirect_draw_arguments_are_wgpus() {
    use terramp::gpu::gpu_types::SeedDrawArgs;
    // The draw pass hands the arguments to wgpu as they are.
    assert_eq!(size_of::<SeedDrawArgs>(), size_of::<wgpu::util::DrawIndexedIndirectArgs>());
    let args = SeedDrawArgs {
        index_count: 1,
        instance_count: 2,
        first_index: 3,
        base_vertex: -4,
        first_instance: 5,
    };
    let wgpu_args = wgpu::util::DrawIndexedIndirectArgs {
        index_count: 1,
        instance_count: 2,
        first_index: 3,
        base_vertex: -4,
        first_instance: 5,
    };
    assert_eq!(bytemuck::bytes_of(&args), wgpu_args.as_bytes());
}
