//! The work a pass submits, read off the plan as the session encodes it (the same instance
//! and count defaults), so the work counters stand beside the GPU's own statistics.

use framelab_core::plan::{ColorTarget, DepthTarget, PassOp};
use framelab_core::timing::counters::Work;

use super::Session;

impl Session {
    /// The draws, dispatches, instances, indices, vertices, render area and threads plan pass
    /// `i` submits.
    pub fn work(&self, i: usize) -> Work {
        let mut w = Work::default();
        let Some(pass) = self.plan.passes.get(i) else {
            return w;
        };
        match &pass.op {
            PassOp::Raster(r) => {
                w.render_area = self.render_area(&r.color, r.depth.as_ref());
                for d in &r.draws {
                    let mesh = d.mesh.map(|m| &self.meshes[m]);
                    let instances = if d.instances == 1 {
                        mesh.map_or(1, |m| m.instance_count.max(1))
                    } else {
                        d.instances
                    };
                    let (count, indexed) = match mesh.and_then(|m| m.index.as_ref()) {
                        Some((_, _, n)) => (d.count.unwrap_or(*n), true),
                        None => (d.count.or(mesh.map(|m| m.vertex_count)).unwrap_or(3), false),
                    };
                    w.add_draw(d.indirect.is_some(), instances, count, indexed);
                }
            }
            PassOp::VkRaster(r) => {
                w.render_area = self.render_area(&r.color, r.depth.as_ref());
                for d in &r.draws {
                    w.add_draw(
                        d.indirect.is_some(),
                        d.instances,
                        d.count,
                        d.index.is_some(),
                    );
                }
            }
            PassOp::Compute(c) => {
                w.dispatches = c.dispatches.len() as u64;
                let module = self.modules.get(c.shader).map(|m| &m.reflection.module);
                for d in &c.dispatches {
                    let Some([x, y, z]) = d.groups.filter(|_| d.indirect.is_none()) else {
                        w.indirect += 1;
                        continue;
                    };
                    let entry = d.entry.as_ref().unwrap_or(&c.entry);
                    let size = module.and_then(|m| {
                        m.entry_points
                            .iter()
                            .find(|e| &e.name == entry)
                            .map(|e| e.workgroup_size)
                    });
                    if let Some([a, b, c]) = size {
                        w.threads += [x, y, z, a, b, c]
                            .iter()
                            .map(|&n| u64::from(n))
                            .product::<u64>();
                    }
                }
            }
            PassOp::VkCompute(c) => {
                w.dispatches = c.dispatches.len() as u64;
                w.indirect = c.dispatches.iter().filter(|d| d.indirect.is_some()).count() as u64;
            }
            _ => {}
        }
        w
    }

    /// Pixels of the largest attachment at the mip the pass renders to.
    fn render_area(&self, color: &[ColorTarget], depth: Option<&DepthTarget>) -> u64 {
        color
            .iter()
            .map(|c| (c.texture, c.mip))
            .chain(depth.map(|d| (d.texture, d.mip)))
            .filter_map(|(t, mip)| {
                let size = self.plan.textures.get(t)?.size;
                Some(u64::from((size.width >> mip).max(1)) * u64::from((size.height >> mip).max(1)))
            })
            .max()
            .unwrap_or(0)
    }
}
