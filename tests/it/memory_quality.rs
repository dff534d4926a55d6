//! Quality of the aliasing plan on random frames: the median plan is within 1.10x of the lower
//! bound (the largest sum of simultaneously live bytes). The worst case is printed for the
//! README. This is a property of the placement, not a timing.

use framelab_core::analysis::units::Units;
use framelab_core::analysis::{graph, memory};
use framelab_testkit::synthetic;

#[test]
fn median_plan_is_within_ten_percent_of_the_lower_bound() {
    let mut ratios: Vec<f64> = Vec::new();
    for seed in 0..300u64 {
        let passes = 20 + (seed as usize * 37) % 400;
        let resources = passes * (1 + seed as usize % 4);
        let model = synthetic::frame(passes, resources, seed);
        let units = Units::new(&model);
        let g = graph::build(&model, &units);
        let order = graph::order(&model, &g).unwrap();
        let plan = memory::plan(&model, &order);
        if seed < 40 {
            // No two resources share bytes while both are alive.
            let live: Vec<_> = plan
                .resources
                .iter()
                .filter(|r| r.lifetime.is_some())
                .collect();
            let end = order.len() as u32;
            let span = |r: &memory::Placed| {
                if r.persistent {
                    (0, end)
                } else {
                    r.lifetime.map(|l| (l.first, l.last)).unwrap()
                }
            };
            for (i, a) in live.iter().enumerate() {
                for b in &live[..i] {
                    let (sa, sb) = (span(a), span(b));
                    let time = sa.0 <= sb.1 && sb.0 <= sa.1;
                    let bytes = a.offset < b.offset + b.bytes && b.offset < a.offset + a.bytes;
                    assert!(
                        a.pool != b.pool || !(time && bytes),
                        "seed {seed}: {} and {} overlap",
                        a.resource,
                        b.resource
                    );
                }
            }
        }
        let t = &plan.total;
        assert!(
            t.aliased_bytes >= t.lower_bound_bytes,
            "seed {seed}: plan below the lower bound"
        );
        ratios.push(t.aliased_bytes as f64 / t.lower_bound_bytes.max(1) as f64);
    }
    ratios.sort_by(f64::total_cmp);
    let median = ratios[ratios.len() / 2];
    let worst = ratios[ratios.len() - 1];
    eprintln!(
        "aliasing plan / lower bound over {} random frames: median {median:.3}, worst {worst:.3}",
        ratios.len()
    );
    assert!(median <= 1.10, "median {median:.3}");
}
