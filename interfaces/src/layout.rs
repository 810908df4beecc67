//! Layout description of the wire types: every message and every struct inside one is
//! declared through [`wire_struct!`], which defines the `#[repr(C)]` type *and* a table of
//! its fields (name, offset, type, unit, meaning). The table drives the generic checks
//! (every `f64` finite), the byte views, and the generated tables of `docs/INTERFACES.md`,
//! so the document cannot drift from the code.
//!
//! Every wire type is plain old data: its fields are `f64`, `i64`, `u64`, `u32`, `u8`,
//! arrays of those, or other wire types, with no implicit padding (checked at compile
//! time). Hence every byte pattern of the right length is a value of the type (maybe an
//! invalid one, which `validate()` then rejects), and the byte view of a value is fully
//! initialised.

use core::mem::{MaybeUninit, size_of};

/// Scalar types allowed in a wire type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scalar {
    F64,
    I64,
    U64,
    U32,
    U8,
}

impl Scalar {
    /// Name of the scalar as written in the interface document.
    pub const fn name(self) -> &'static str {
        match self {
            Scalar::F64 => "f64",
            Scalar::I64 => "i64",
            Scalar::U64 => "u64",
            Scalar::U32 => "u32",
            Scalar::U8 => "u8",
        }
    }
}

/// What one element of a field is: a scalar or a nested wire struct.
#[derive(Clone, Copy)]
pub enum Element {
    Scalar(Scalar),
    Struct {
        name: &'static str,
        size: usize,
        fields: fn() -> &'static [FieldInfo],
    },
}

/// One field of a wire struct.
#[derive(Clone, Copy)]
pub struct FieldInfo {
    pub name: &'static str,
    pub offset: usize,
    pub size: usize,
    /// The element type (the innermost type of an array).
    pub element: Element,
    /// How many elements the field holds (1 for a scalar, the product of array lengths).
    pub count: usize,
    /// Array dimensions in C order, e.g. `[8][3]`, empty for a scalar.
    pub dims: fn() -> Vec<usize>,
    pub unit: &'static str,
    pub doc: &'static str,
}

impl FieldInfo {
    /// The type as C writes it: `f64`, `f64[3]`, `PlanSample[2048]`, `f64[8][3]`.
    pub fn c_type(&self) -> String {
        let base = match self.element {
            Element::Scalar(s) => s.name(),
            Element::Struct { name, .. } => name,
        };
        let mut out = String::from(base);
        for d in (self.dims)() {
            out.push_str(&format!("[{d}]"));
        }
        out
    }
}

/// A type that may appear as a field of a wire struct.
///
/// # Safety
/// Implementors must be plain old data: no padding, no pointers, and every bit pattern
/// a valid value.
pub unsafe trait Plain: Copy + 'static {
    const ELEMENT: Element;
    const COUNT: usize;
    fn dims() -> Vec<usize>;
}

macro_rules! plain_scalar {
    ($($t:ty => $s:ident),*) => {$(
        // SAFETY: primitive numbers have no padding and accept every bit pattern.
        unsafe impl Plain for $t {
            const ELEMENT: Element = Element::Scalar(Scalar::$s);
            const COUNT: usize = 1;
            fn dims() -> Vec<usize> {
                Vec::new()
            }
        }
    )*};
}
plain_scalar!(f64 => F64, i64 => I64, u64 => U64, u32 => U32, u8 => U8);

// SAFETY: an array of plain elements is plain (arrays have no padding between elements).
unsafe impl<T: Plain, const N: usize> Plain for [T; N] {
    const ELEMENT: Element = T::ELEMENT;
    const COUNT: usize = N * T::COUNT;
    fn dims() -> Vec<usize> {
        let mut d = vec![N];
        d.extend(T::dims());
        d
    }
}

/// A fixed-layout wire type declared with [`wire_struct!`].
///
/// # Safety
/// Implemented only by [`wire_struct!`], which guarantees `#[repr(C)]`, plain fields and
/// no padding.
pub unsafe trait Wire: Plain + Transport {
    /// Name in the interface document.
    const NAME: &'static str;
    /// Type name in iceoryx2's type check (`wingman::<NAME>`), the same with or without
    /// the `iceoryx2` feature.
    const TYPE_NAME: &'static str;
    /// One paragraph for the interface document.
    const DOC: &'static str;
    /// Every field, in declaration (and offset) order.
    fn fields() -> &'static [FieldInfo];

    /// The value's bytes in memory (native endianness: little-endian on every supported
    /// target).
    fn as_bytes(&self) -> &[u8] {
        // SAFETY: `Wire` types have no padding, so all `size_of::<Self>()` bytes are
        // initialised.
        unsafe {
            core::slice::from_raw_parts((self as *const Self).cast::<u8>(), size_of::<Self>())
        }
    }

    /// A copy of the value whose bytes are `bytes`. Every bit pattern is a value; whether
    /// it is a *valid* message is for `validate()` to say.
    fn read_from_bytes(bytes: &[u8]) -> Result<Self, WrongLength> {
        if bytes.len() != size_of::<Self>() {
            return Err(WrongLength {
                expected: size_of::<Self>(),
                found: bytes.len(),
            });
        }
        // SAFETY: the length matches, every bit pattern is a value, and the read is
        // unaligned-safe.
        Ok(unsafe { core::ptr::read_unaligned(bytes.as_ptr().cast::<Self>()) })
    }

    /// Zero-fills `slot` in place (for loaned shared-memory samples too large for the
    /// stack) and returns it initialised.
    fn zeroed_in(slot: &mut MaybeUninit<Self>) -> &mut Self {
        // SAFETY: all-zero bytes are a value of every plain type.
        unsafe {
            slot.as_mut_ptr().write_bytes(0, 1);
            slot.assume_init_mut()
        }
    }

    /// A zero-filled value (all counts zero, all numbers 0.0).
    fn zeroed() -> Self {
        // SAFETY: all-zero bytes are a value of every plain type.
        unsafe { core::mem::zeroed() }
    }

    /// Name of the first `f64` field holding NaN or an infinity, if any (arrays are checked
    /// element by element, nested structs recursively, unused slots included).
    fn first_non_finite(&self) -> Option<&'static str> {
        first_non_finite_in(self.as_bytes(), Self::fields())
    }
}

/// What a wire type needs to travel: iceoryx2's `ZeroCopySend` with the `iceoryx2`
/// feature, nothing without it (code that only computes with messages links no IPC).
#[cfg(feature = "iceoryx2")]
pub trait Transport: iceoryx2::prelude::ZeroCopySend {}
#[cfg(feature = "iceoryx2")]
impl<T: iceoryx2::prelude::ZeroCopySend> Transport for T {}
/// What a wire type needs to travel: nothing without the `iceoryx2` feature.
#[cfg(not(feature = "iceoryx2"))]
pub trait Transport {}
#[cfg(not(feature = "iceoryx2"))]
impl<T> Transport for T {}

/// `read_from_bytes` was given the wrong number of bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("expected {expected} bytes, got {found}")]
pub struct WrongLength {
    pub expected: usize,
    pub found: usize,
}

fn first_non_finite_in(bytes: &[u8], fields: &[FieldInfo]) -> Option<&'static str> {
    for f in fields {
        match f.element {
            Element::Scalar(Scalar::F64) => {
                let block = &bytes[f.offset..f.offset + f.size];
                for chunk in block.chunks_exact(8) {
                    let mut b = [0u8; 8];
                    b.copy_from_slice(chunk);
                    if !f64::from_ne_bytes(b).is_finite() {
                        return Some(f.name);
                    }
                }
            }
            Element::Scalar(_) => {}
            Element::Struct { size, fields, .. } => {
                let inner = fields();
                for k in 0..f.count {
                    let start = f.offset + k * size;
                    if let Some(name) = first_non_finite_in(&bytes[start..start + size], inner) {
                        return Some(name);
                    }
                }
            }
        }
    }
    None
}

/// Declares a wire struct and its field table. Each field carries its unit in brackets
/// after the type; doc comments become the field's meaning in the interface document.
#[macro_export]
#[doc(hidden)]
macro_rules! wire_struct {
    (
        $(#[doc = $doc:literal])*
        #[type_name($tn:literal)]
        pub struct $name:ident {
            $(
                $(#[doc = $fdoc:literal])*
                pub $field:ident : $ty:ty [$unit:literal],
            )*
        }
    ) => {
        $(#[doc = $doc])*
        #[derive(Debug, Clone, Copy, PartialEq)]
        #[repr(C)]
        pub struct $name {
            $( $(#[doc = $fdoc])* pub $field: $ty, )*
        }

        const _: () = assert!(
            ::core::mem::size_of::<$name>() == 0 $(+ ::core::mem::size_of::<$ty>())*,
            concat!("wire type ", stringify!($name), " has implicit padding"),
        );

        // SAFETY: `#[repr(C)]`, every field is `Plain` (numbers, arrays of them, other wire
        // structs) and there is no padding (both checked here), so the bytes mean the same
        // in every process: what iceoryx2's derive would check, and more.
        #[cfg(feature = "iceoryx2")]
        unsafe impl $crate::ZeroCopySend for $name {
            unsafe fn type_name() -> &'static str {
                $tn
            }
        }

        // SAFETY: `#[repr(C)]`, every field is `Plain` (checked by the bounds below), and
        // the sizes add up, so there is no padding.
        unsafe impl $crate::layout::Plain for $name {
            const ELEMENT: $crate::layout::Element = $crate::layout::Element::Struct {
                name: stringify!($name),
                size: ::core::mem::size_of::<$name>(),
                fields: <$name as $crate::layout::Wire>::fields,
            };
            const COUNT: usize = 1;
            fn dims() -> Vec<usize> {
                Vec::new()
            }
        }

        // SAFETY: see the `Plain` impl above.
        unsafe impl $crate::layout::Wire for $name {
            const NAME: &'static str = stringify!($name);
            const TYPE_NAME: &'static str = $tn;
            const DOC: &'static str = concat!($($doc, "\n",)*);
            fn fields() -> &'static [$crate::layout::FieldInfo] {
                const FIELDS: &[$crate::layout::FieldInfo] = &[$(
                    $crate::layout::FieldInfo {
                        name: stringify!($field),
                        offset: ::core::mem::offset_of!($name, $field),
                        size: ::core::mem::size_of::<$ty>(),
                        element: <$ty as $crate::layout::Plain>::ELEMENT,
                        count: <$ty as $crate::layout::Plain>::COUNT,
                        dims: <$ty as $crate::layout::Plain>::dims,
                        unit: $unit,
                        doc: concat!($($fdoc,)*),
                    },
                )*];
                FIELDS
            }
        }
    };
}

/// Declares a `u32`-coded enum carried in a wire field, with its table for the document.
#[macro_export]
#[doc(hidden)]
macro_rules! wire_enum {
    (
        $(#[doc = $doc:literal])*
        pub enum $name:ident {
            $( $(#[doc = $vdoc:literal])* $variant:ident = $value:literal, )*
        }
    ) => {
        $(#[doc = $doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        #[repr(u32)]
        pub enum $name {
            $( $(#[doc = $vdoc])* $variant = $value, )*
        }

        impl $name {
            /// Every variant, in declaration order.
            pub const ALL: &'static [$name] = &[$($name::$variant,)*];

            /// The value carried on the wire.
            pub const fn to_wire(self) -> u32 {
                self as u32
            }

            /// The variant carried by `value`, if it is a known one.
            pub const fn from_wire(value: u32) -> Option<Self> {
                match value {
                    $( $value => Some($name::$variant), )*
                    _ => None,
                }
            }

            /// Variant name as the document and logs spell it.
            pub const fn name(self) -> &'static str {
                match self {
                    $( $name::$variant => stringify!($variant), )*
                }
            }
        }

        impl $crate::layout::WireEnum for $name {
            const NAME: &'static str = stringify!($name);
            const DOC: &'static str = concat!($($doc, "\n",)*);
            fn variants() -> &'static [(&'static str, u32, &'static str)] {
                &[$( (stringify!($variant), $value, concat!($($vdoc,)*)), )*]
            }
        }
    };
}

/// A `u32`-coded enum of the protocol, for the interface document.
pub trait WireEnum {
    const NAME: &'static str;
    const DOC: &'static str;
    /// (name, wire value, meaning) of each variant.
    fn variants() -> &'static [(&'static str, u32, &'static str)];
}
