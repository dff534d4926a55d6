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
            writes: false
        }),
        "the texel buffer is only read (OpImageRead)"
    );
    assert_eq!(
        mpv.get(&(0, 1)),
        Some(&Usage {
            reads: false,
            writes: true
        }),
        "the storage image is only written (OpImageWrite)"
    );
    // A sampled-only fragment shader neither writes nor reads storage; its sampled texture
    // is read through OpImageSampleImplicitLod, which is no storage access.
    let fragment = usage(&fixture("mpv_testsrc_f5/sh83")).unwrap();
    assert!(fragment.values().all(|u| !u.writes));
}
