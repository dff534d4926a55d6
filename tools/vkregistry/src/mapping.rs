//! How GFXReconstruct encodes a declaration, as a registry-independent `Ty` tree (structures
//! and enums by name; `emit` turns names into table indices). The rules follow what
//! GFXReconstruct's generated encoders write for each kind of declaration, so a decoder
//! driven by these types reads a capture in step with the writer.

use crate::decl::Decl;
use crate::vkxml::{Member, Registry};

/// `registry.rs`'s `Ty` with names where the tables hold indices: indices are known only
/// once every structure and enum has been collected.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Ty {
    U8,
    U16,
    U32,
    I32,
    U64,
    I64,
    F32,
    F64,
    Enum(String),
    Flags32,
    Flags64,
    Handle,
    Address,
    Struct(String),
    PNext,
    Ptr(Box<Ty>),
    /// A pointer the registry gives a length, or a fixed array: always a list, even where
    /// GFXReconstruct wrote it as a pointer to one element.
    Arr(Box<Ty>),
    Str,
    Strs,
    Opaque,
}

/// Types from platform headers, which the registry names but does not define. GFXReconstruct
/// writes each as the C type it is on its platform.
enum Platform {
    /// An opaque object only ever passed by pointer (`Display*`, `ANativeWindow*`): the
    /// pointer is written as an address.
    Object,
    /// A typedef of a pointer (`HWND`, `MTLDevice_id`): an address by value; a pointer to
    /// one is written like `void**`.
    PointerLike,
    /// An integer typedef, written at its own width.
    Int(Ty),
}

fn platform(name: &str) -> Option<Platform> {
    Some(match name {
        "Display" | "wl_display" | "wl_surface" | "xcb_connection_t" | "IDirectFB"
        | "IDirectFBSurface" | "_screen_context" | "_screen_window" | "ANativeWindow"
        | "AHardwareBuffer" | "CAMetalLayer" => Platform::Object,
        "HANDLE" | "HINSTANCE" | "HWND" | "HMONITOR" | "IOSurfaceRef" | "MTLDevice_id"
        | "MTLCommandQueue_id" | "MTLBuffer_id" | "MTLTexture_id" | "MTLSharedEvent_id"
        | "VkRemoteAddressNV" => Platform::PointerLike,
        "xcb_window_t" | "xcb_visualid_t" | "zx_handle_t" | "DWORD" => Platform::Int(Ty::U32),
        "int" => Platform::Int(Ty::I32),
        // `unsigned long` on X11, written as `size_t`.
        "Window" | "VisualID" | "RROutput" => Platform::Int(Ty::U64),
        // GFXReconstruct writes both as 64-bit values.
        "GgpStreamDescriptor" | "GgpFrameToken" => Platform::Int(Ty::U64),
        _ => return None,
    })
}

fn scalar(name: &str) -> Option<Ty> {
    Some(match name {
        "VkBool32" | "VkSampleMask" | "uint32_t" => Ty::U32,
        "int32_t" => Ty::I32,
        "uint64_t" | "size_t" | "VkDeviceSize" | "VkDeviceAddress" => Ty::U64,
        "int64_t" => Ty::I64,
        "uint16_t" => Ty::U16,
        "uint8_t" => Ty::U8,
        "float" => Ty::F32,
        "double" => Ty::F64,
        "VkFlags" => Ty::Flags32,
        "VkFlags64" => Ty::Flags64,
        _ => return None,
    })
}

pub struct Mapper<'a> {
    pub reg: &'a Registry,
}

impl Mapper<'_> {
    fn category(&self, name: &str) -> Option<&str> {
        self.reg.types.get(name)?.category.as_deref()
    }

    /// A type written by value.
    pub fn value(&self, name: &str) -> Ty {
        let name = self.reg.resolve_type(name);
        if let Some(ty) = scalar(name) {
            return ty;
        }
        if let Some(p) = platform(name) {
            return match p {
                Platform::Object => Ty::Opaque,
                Platform::PointerLike => Ty::Address,
                Platform::Int(ty) => ty,
            };
        }
        match self.category(name) {
            Some("enum") => {
                // 64-bit flag bits are written as a flags value, not an enumerant.
                let wide = self.reg.enums.get(name).and_then(|e| e.bitwidth) == Some(64);
                if wide {
                    Ty::Flags64
                } else {
                    Ty::Enum(name.to_owned())
                }
            }
            Some("bitmask") => {
                let code = self
                    .reg
                    .types
                    .get(name)
                    .map(|t| t.code.as_str())
                    .unwrap_or("");
                if code.contains("VkFlags64") {
                    Ty::Flags64
                } else {
                    Ty::Flags32
                }
            }
            Some("handle") => Ty::Handle,
            Some("struct" | "union") => Ty::Struct(name.to_owned()),
            Some("funcpointer") => Ty::Address,
            _ => Ty::Opaque,
        }
    }

    /// A pointer to one `name`, or an array of them.
    fn pointee(&self, name: &str, has_len: bool) -> Ty {
        let name = self.reg.resolve_type(name);
        match name {
            "char" => return Ty::Str,
            "void" if has_len => return Ty::Arr(Box::new(Ty::U8)),
            "void" => return Ty::Address,
            _ => {}
        }
        match platform(name) {
            Some(Platform::Object) => Ty::Address,
            Some(Platform::PointerLike) => Ty::Ptr(Box::new(Ty::U64)),
            _ => match self.value(name) {
                Ty::Opaque => Ty::Opaque,
                ty if has_len => Ty::Arr(Box::new(ty)),
                ty => Ty::Ptr(Box::new(ty)),
            },
        }
    }

    /// A pointer to pointers to `name`.
    fn pointee_of_pointers(&self, name: &str, has_len: bool) -> Ty {
        let name = self.reg.resolve_type(name);
        match (name, platform(name)) {
            ("char", _) => Ty::Strs,
            // An output `void**` or `AHardwareBuffer**` is a pointer to one address. An array
            // of pointers (`const void* const* pParams`) has no encoding GFXReconstruct
            // defines.
            ("void", _) | (_, Some(Platform::Object)) if !has_len => Ty::Ptr(Box::new(Ty::U64)),
            _ => Ty::Opaque,
        }
    }

    pub fn decl(&self, d: &Decl, len: Option<&str>) -> Ty {
        if d.name == "pNext" && d.pointers == 1 {
            return Ty::PNext;
        }
        // GFXReconstruct writes a bit field as a whole 32-bit value and a matrix as one flat
        // array, but only acceleration-structure instance data has either, and no call
        // reaches it; left unread, a future use shows up as undecoded instead of misread.
        if d.bit_field || d.dims > 1 || (d.dims == 1 && d.pointers > 0) {
            return Ty::Opaque;
        }
        match (d.pointers, d.dims) {
            (0, 0) => self.value(&d.type_name),
            (0, _) if d.type_name == "char" => Ty::Str,
            // A fixed array is written with the pointer preamble, like `T*` with a length.
            // An array of something unreadable is as unreadable as one element.
            (0, _) => match self.value(&d.type_name) {
                Ty::Opaque => Ty::Opaque,
                ty => Ty::Arr(Box::new(ty)),
            },
            (1, _) => self.pointee(&d.type_name, len.is_some()),
            (2, _) => self.pointee_of_pointers(&d.type_name, len.is_some()),
            _ => Ty::Opaque,
        }
    }

    pub fn member(&self, m: &Member) -> Ty {
        self.decl(&m.decl, m.len.as_deref())
    }

    /// A command parameter. The descriptor-update-template calls' `pData` (a `void*` without
    /// a length) is not an address in a capture: GFXReconstruct writes the template's
    /// descriptors there in a layout of its own, which only a hand-written reader follows.
    pub fn param(&self, command: &str, p: &Member) -> Ty {
        const TEMPLATE_CALLS: [&str; 3] = [
            "vkUpdateDescriptorSetWithTemplate",
            "vkUpdateDescriptorSetWithTemplateKHR",
            "vkCmdPushDescriptorSetWithTemplateKHR",
        ];
        if p.decl.name == "pData" && TEMPLATE_CALLS.contains(&command) {
            return Ty::Opaque;
        }
        self.member(p)
    }

    /// A command's return value: `None` for `void`.
    pub fn ret(&self, d: &Decl) -> Option<Ty> {
        if d.type_name == "void" && d.pointers == 0 {
            return None;
        }
        Some(self.decl(d, None))
    }

    /// The members GFXReconstruct writes for a union: the one member it picks for the
    /// unions it handles by hand, an unreadable placeholder for the rest.
    pub fn union_members(&self, name: &str) -> Vec<(String, Ty)> {
        let (member, ty) = match name {
            "VkClearColorValue" => ("uint32", Ty::Arr(Box::new(Ty::U32))),
            "VkClearValue" => ("color", Ty::Struct("VkClearColorValue".to_owned())),
            "VkPipelineExecutableStatisticValueKHR" => ("u64", Ty::U64),
            "VkDeviceOrHostAddressKHR" | "VkDeviceOrHostAddressConstKHR" => {
                ("deviceAddress", Ty::U64)
            }
            _ => (name, Ty::Opaque),
        };
        vec![(member.to_owned(), ty)]
    }

    /// The structures and enumerated types `ty` names directly.
    pub fn visit<'t>(ty: &'t Ty, out: &mut Vec<&'t Ty>) {
        match ty {
            Ty::Ptr(inner) | Ty::Arr(inner) => Self::visit(inner, out),
            Ty::Struct(_) | Ty::Enum(_) => out.push(ty),
            _ => {}
        }
    }
}
