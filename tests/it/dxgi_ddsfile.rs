//! Checks framelab's DXGI table against ddsfile's, an independent implementation of the same
//! enumeration, so sizes are not only compared with values typed in this repository.

use ddsfile::{DataFormat, DxgiFormat};
use framelab_core::capture::dxgi::{self, Layout};
use num_traits::FromPrimitive;

fn normalise(name: &str) -> String {
    name.to_ascii_uppercase().replace('_', "")
}

#[test]
fn names_and_sizes_agree_with_ddsfile() {
    let mut compared = 0;
    for info in dxgi::all() {
        let Some(theirs) = DxgiFormat::from_u32(info.value) else {
            continue;
        };
        let their_name = format!("{theirs:?}");
        let ours = if info.name == "OPAQUE_420" {
            "FORMAT_420_OPAQUE"
        } else {
            info.name
        };
        assert_eq!(
            normalise(ours),
            normalise(&their_name),
            "value {}",
            info.value
        );

        if let Some(bpp) = theirs.get_bits_per_pixel() {
            let texels = info.block_width * info.block_height;
            assert_eq!(
                info.bits_per_element / texels,
                u32::from(bpp),
                "{}",
                info.name
            );
            compared += 1;
        }
        if let Some(block) = theirs.get_block_size() {
            assert_eq!(info.layout, Layout::BlockCompressed, "{}", info.name);
            assert_eq!(info.bits_per_element / 8, block, "{}", info.name);
            compared += 1;
        }
        if let (Some(pitch), Some(bytes)) = (theirs.get_pitch(64), info.surface_bytes(64, 1))
            && info.layout == Layout::Linear
        {
            assert_eq!(u64::from(pitch), bytes, "{} row pitch", info.name);
        }
    }
    assert!(compared >= 100, "only {compared} formats compared");
}
