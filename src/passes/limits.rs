//! How it works: what a device must allow for terramp's passes, so that a device the host made
//! (`Gpu::from_host`) is refused up front, naming the limit, instead of failing at the first
//! pipeline it cannot hold. The bindings each pipeline uses are read from `PIPELINE_BINDINGS`
//! (the same tables that build the bind groups, checked against the WGSL by `tests/shaders.rs`):
//! per pipeline (a shader's entry point with every group it binds) and per stage, the storage
//! buffers, uniform buffers, sampled and storage textures and samplers it sees, and the number of
//! bind groups. Everything else is wgpu's default limits, which terramp's own device asks for at
//! least; the sizes that depend on the settings (the viewport against the largest texture, the
//! caches against texture-array layers, the seeds against the largest storage binding) are
//! checked by `Renderer::new` against the settings, as on any device.

use std::collections::BTreeMap;

use wgpu::ShaderStages;

use super::PIPELINE_BINDINGS;
use crate::gpu::bindings::{BindingKind, PipelineBindings};

/// A limit of a device short of what terramp needs.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "this GPU device allows {has} for {name} and terramp's passes need {needed}: make the device \
     with at least terramp::passes::limits::needed_limits()"
)]
pub struct LimitShort {
    /// wgpu's name of the limit (`max_storage_buffers_per_shader_stage`).
    pub name: &'static str,
    /// What terramp needs.
    pub needed: u64,
    /// What the device allows.
    pub has: u64,
}

/// What one pipeline stage sees, counted by kind.
#[derive(Debug, Default, Clone, Copy)]
struct StageUse {
    storage_buffers: u32,
    uniform_buffers: u32,
    sampled_textures: u32,
    storage_textures: u32,
    samplers: u32,
}

/// The limits to make a device for terramp with: wgpu's defaults, with the per-stage binding
/// counts and the bind groups that terramp's pipelines use. The default settings fit wgpu's
/// default sizes; settings that need more (a larger viewport, caches or seed buffers) need the
/// device's sizes raised, and `Renderer::new` names the one short.
pub fn needed_limits() -> wgpu::Limits {
    let uses = stage_uses(PIPELINE_BINDINGS);
    let most = |f: fn(&StageUse) -> u32| uses.values().map(f).max().unwrap_or(0);
    let groups = PIPELINE_BINDINGS.iter().map(|p| p.group + 1).max().unwrap_or(0);
    wgpu::Limits {
        max_storage_buffers_per_shader_stage: most(|u| u.storage_buffers),
        max_uniform_buffers_per_shader_stage: most(|u| u.uniform_buffers),
        max_sampled_textures_per_shader_stage: most(|u| u.sampled_textures),
        max_storage_textures_per_shader_stage: most(|u| u.storage_textures),
        max_samplers_per_shader_stage: most(|u| u.samplers),
        max_bind_groups: groups,
        ..wgpu::Limits::default()
    }
}

/// The first limit of `has` short of `needed_limits`, if any, leaving out the sizes that depend
/// on the settings (checked against them where they are used).
pub fn check_limits(has: &wgpu::Limits) -> Result<(), LimitShort> {
    let needed = wgpu::Limits {
        max_texture_dimension_2d: 1,
        max_texture_array_layers: 1,
        max_storage_buffer_binding_size: 1,
        max_buffer_size: 1,
        ..needed_limits()
    };
    let mut short = None;
    needed.check_limits_with_fail_fn(has, false, |name, needed, has| {
        short.get_or_insert(LimitShort { name, needed, has });
    });
    short.map_or(Ok(()), Err)
}

/// Per pipeline (shader, entry point) and stage (its bits), what its bind groups give that stage
/// to see.
fn stage_uses(tables: &[PipelineBindings]) -> BTreeMap<(&'static str, &'static str, u32), StageUse> {
    let mut uses: BTreeMap<(&str, &str, u32), StageUse> = BTreeMap::new();
    for table in tables {
        for &entry_point in table.entry_points {
            for stage in [ShaderStages::VERTEX, ShaderStages::FRAGMENT, ShaderStages::COMPUTE] {
                let seen = uses.entry((table.shader.name, entry_point, stage.bits())).or_default();
                for binding in table.bindings.iter().filter(|b| b.visibility.contains(stage)) {
                    let count = match binding.kind {
                        BindingKind::Storage { .. } => &mut seen.storage_buffers,
                        BindingKind::Uniform { .. } => &mut seen.uniform_buffers,
                        BindingKind::Texture { .. } => &mut seen.sampled_textures,
                        BindingKind::StorageTexture { .. } => &mut seen.storage_textures,
                        BindingKind::Sampler(_) => &mut seen.samplers,
                    };
                    *count += 1;
                }
            }
        }
    }
    uses
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seed_selections_settle_step_sees_the_most_storage_buffers() {
        let uses = stage_uses(PIPELINE_BINDINGS);
        let most = uses.values().map(|u| u.storage_buffers).max().unwrap();
        let (shader, entry_point, _) = uses.iter().find(|(_, u)| u.storage_buffers == most).unwrap().0;
        assert_eq!((*shader, *entry_point, most), ("seed_select", "settle", 15));
    }

    #[test]
    fn a_device_short_of_one_limit_is_refused_naming_it() {
        let needed = needed_limits();
        assert_eq!(check_limits(&needed), Ok(()));
        let short = wgpu::Limits {
            max_storage_buffers_per_shader_stage: needed.max_storage_buffers_per_shader_stage - 1,
            ..needed.clone()
        };
        let error = check_limits(&short).unwrap_err();
        assert_eq!(error.name, "max_storage_buffers_per_shader_stage");
        assert_eq!(error.needed, u64::from(needed.max_storage_buffers_per_shader_stage));
        assert!(error.to_string().contains("needed_limits"), "{error}");
    }
}
