//! What real modules' code does with their storage bindings: the mpv compute shader reads its
//! storage texel buffer (declared without `readonly`, so only the code tells) and writes its
//! storage image. (naga's modules, whose storage textures are read or written by the code, are
//! covered by the planted write-after-read stream in the synchronization tests.)

use super::*;

#[test]
fn storage_reads_and_writes_come_from_the_code() {
    let mpv = usage(&fixture("mpv_testsrc_f5/sh73")).unwrap();
    assert_eq!(
        mpv.get(&(0, 0)),
        Some(&Usage {
            reads: true,
            writes: false,
            used: true,
        }),
        "the texel buffer is only read (OpImageRead)"
    );
    assert_eq!(
        mpv.get(&(0, 1)),
        Some(&Usage {
            reads: false,
            writes: true,
            used: true,
        }),
        "the storage image is only written (OpImageWrite)"
    );
    // A sampled-only fragment shader neither writes nor reads storage; its sampled texture
    // is read through OpImageSampleImplicitLod, which is no storage access.
    let fragment = usage(&fixture("mpv_testsrc_f5/sh83")).unwrap();
    assert!(fragment.values().all(|u| !u.writes));
    assert!(
        fragment.values().all(|u| u.used),
        "every binding it declares is sampled"
    );
}

/// A binding the code never names is declared but not statically used; one only passed to
/// a function is used.
#[test]
fn static_use_is_naming_the_variable_in_code() {
    let words = combined_sampler_module(Shape {
        via_function: true,
        second_call: true,
        ..Shape::default()
    });
    let u = usage(&words).unwrap();
    assert!(u[&(1, 3)].used && u[&(1, 4)].used);
    // The second variable declared and never passed (main samples the first itself).
    let words = combined_sampler_module(Shape {
        second_call: true,
        ..Shape::default()
    });
    let u = usage(&words).unwrap();
    assert!(u[&(1, 3)].used);
    assert!(
        !u[&(1, 4)].used,
        "declared at set 1 binding 4, never named by code"
    );
}
