//! How it works: the machinery of `gpu::layout`: `wgsl_constants!` (Rust constants listed with
//! their WGSL type and literal for the prelude) and `packed_word!` (a bit-packed u32 word as a
//! Rust struct with `pack`/`unpack`, described for the prelude's WGSL twin). Like its parent it
//! imports nothing of the crate.

/// A value the WGSL prelude can declare.
pub trait WgslLiteral {
    /// The WGSL type and literal, e.g. `("u32", "256u")`.
    fn wgsl(&self) -> (&'static str, String);
}

impl WgslLiteral for u32 {
    fn wgsl(&self) -> (&'static str, String) {
        ("u32", format!("{self}u"))
    }
}

impl WgslLiteral for f32 {
    fn wgsl(&self) -> (&'static str, String) {
        // Debug always writes a decimal point or an exponent: a float literal to WGSL too.
        ("f32", format!("{self:?}"))
    }
}

impl WgslLiteral for i32 {
    fn wgsl(&self) -> (&'static str, String) {
        ("i32", format!("{self}i"))
    }
}

/// Defines constants and a function listing them (name, WGSL type, literal) for the prelude.
macro_rules! wgsl_constants {
    ($list:ident: $($(#[$meta:meta])* pub const $name:ident: $ty:ty = $value:expr;)*) => {
        $($(#[$meta])* pub const $name: $ty = $value;)*

        /// The constants of this block as the prelude declares them: name, WGSL type, literal.
        fn $list() -> Vec<(&'static str, &'static str, String)> {
            vec![$({
                let (ty, literal) = WgslLiteral::wgsl(&$name);
                (stringify!($name), ty, literal)
            }),*]
        }
    };
}

/// One field of a packed word: its name and width in bits (fields are packed from bit 0 up).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BitField {
    /// The field's name, the same in the Rust struct and the WGSL struct.
    pub name: &'static str,
    /// Its width in bits; it sits just above the fields before it.
    pub bits: u32,
}

/// A packed word as the prelude emits it: a WGSL struct of the same name, `pack_<word>` and
/// `unpack_<word>`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PackedWord {
    /// The Rust (and WGSL) struct name.
    pub name: &'static str,
    /// The snake-case name of its pack and unpack functions.
    pub function: &'static str,
    /// Its fields, from bit 0 up.
    pub fields: &'static [BitField],
}

/// Defines a packed u32 word: a Rust struct of its fields, `pack`/`unpack` (each field masked to
/// its width, as WGSL does), and its `PackedWord` description for the prelude.
macro_rules! packed_word {
    ($(#[$meta:meta])* pub struct $name:ident as $function:ident {
        $($(#[$fmeta:meta])* $field:ident: $bits:expr),* $(,)?
    }) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
        pub struct $name {
            $($(#[$fmeta])* pub $field: u32,)*
        }

        impl $name {
            /// The word's layout, as the WGSL prelude declares it.
            pub const WORD: PackedWord = PackedWord {
                name: stringify!($name),
                function: stringify!($function),
                fields: &[$(BitField { name: stringify!($field), bits: $bits }),*],
            };

            /// The fields in one word, each masked to its width.
            pub const fn pack(self) -> u32 {
                let mut word = 0u32;
                let mut shift = 0u32;
                $(
                    word |= (self.$field & mask($bits)) << shift;
                    shift += $bits;
                )*
                let _ = shift;
                word
            }

            /// The fields of `word`.
            pub const fn unpack(word: u32) -> Self {
                let mut shift = 0u32;
                $(
                    let $field = (word >> shift) & mask($bits);
                    shift += $bits;
                )*
                let _ = shift;
                Self { $($field),* }
            }
        }

        const _: () = assert!(0 $(+ $bits)* <= 32, concat!(stringify!($name), " does not fit 32 bits"));
    };
}

/// The low `bits` bits set.
pub const fn mask(bits: u32) -> u32 {
    if bits >= 32 { u32::MAX } else { (1u32 << bits) - 1 }
}
