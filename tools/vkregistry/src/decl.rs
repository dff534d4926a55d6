//! The shape of one C declaration from the registry (`const VkFoo* const* ppFoo`,
//! `uint8_t uuid[VK_UUID_SIZE]`, `uint32_t mask:8`): the encoding depends on how many
//! pointers and array dimensions wrap the type, which `vk-parse` leaves in the text.

use anyhow::{Result, bail};

#[derive(Debug, Clone)]
pub struct Decl {
    pub type_name: String,
    pub name: String,
    /// `*`s between the type and the name.
    pub pointers: usize,
    /// `[N]` suffixes.
    pub dims: usize,
    /// A `:N` bit-field width.
    pub bit_field: bool,
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// The byte offset of `word` in `text` at or after `from`, as a whole identifier.
fn find_word(text: &str, word: &str, from: usize) -> Option<usize> {
    let mut start = from;
    while let Some(found) = text.get(start..)?.find(word) {
        let at = start + found;
        let before = text[..at].chars().next_back();
        let after = text[at + word.len()..].chars().next();
        if !before.is_some_and(is_ident) && !after.is_some_and(is_ident) {
            return Some(at);
        }
        start = at + word.len();
    }
    None
}

impl Decl {
    pub fn parse(code: &str, type_name: &str, name: &str) -> Result<Decl> {
        let Some(type_at) = find_word(code, type_name, 0) else {
            bail!("{name}: type {type_name} not in {code:?}");
        };
        let after_type = type_at + type_name.len();
        let Some(name_at) = find_word(code, name, after_type) else {
            bail!("{name}: name not after the type in {code:?}");
        };
        let suffix = code[name_at + name.len()..].trim_start();
        Ok(Decl {
            type_name: type_name.to_owned(),
            name: name.to_owned(),
            pointers: code[after_type..name_at].matches('*').count(),
            dims: suffix.matches('[').count(),
            bit_field: suffix.starts_with(':'),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shape(code: &str, ty: &str, name: &str) -> (usize, usize, bool) {
        let d = Decl::parse(code, ty, name).unwrap();
        (d.pointers, d.dims, d.bit_field)
    }

    #[test]
    fn shapes() {
        assert_eq!(
            shape(
                "const VkImageCreateInfo* pCreateInfo",
                "VkImageCreateInfo",
                "pCreateInfo"
            ),
            (1, 0, false)
        );
        assert_eq!(
            shape("const char* const*      ppNames", "char", "ppNames"),
            (2, 0, false)
        );
        assert_eq!(
            shape("uint8_t uuid[VK_UUID_SIZE]", "uint8_t", "uuid"),
            (0, 1, false)
        );
        assert_eq!(
            shape("float matrix[3][4]", "float", "matrix"),
            (0, 2, false)
        );
        assert_eq!(shape("uint32_t mask:8", "uint32_t", "mask"), (0, 0, true));
        assert_eq!(
            shape(
                "struct VkBaseOutStructure* pNext",
                "VkBaseOutStructure",
                "pNext"
            ),
            (1, 0, false)
        );
        assert_eq!(
            shape("VkResult vkCreateImage", "VkResult", "vkCreateImage"),
            (0, 0, false)
        );
    }
}
