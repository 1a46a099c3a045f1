//! `enum_mirror!`: an enum that mirrors one of the library's, variant for variant,
//! converting both ways. The layers above name the library's enums their own way —
//! the command line (clap's `ValueEnum`, with a help text per value) and the core
//! description file (serde) — and the hardware layer must not know either crate, so
//! the mirror is written once here and each layer adds its own derives. The `match`
//! is exhaustive both ways: a variant added to the library is a compile error in
//! every mirror until it gets a name there.

/// `enum_mirror! { #[attrs] Name => LibEnum { #[attrs] Variant, … } }`.
#[macro_export]
macro_rules! enum_mirror {
    ($(#[$m:meta])* $name:ident => $lib:ident { $($(#[$vm:meta])* $v:ident),+ $(,)? }) => {
        $(#[$m])*
        pub enum $name {
            $($(#[$vm])* $v),+
        }
        impl From<$name> for $lib {
            fn from(v: $name) -> Self {
                match v {
                    $($name::$v => $lib::$v),+
                }
            }
        }
        impl From<$lib> for $name {
            fn from(v: $lib) -> Self {
                match v {
                    $($lib::$v => $name::$v),+
                }
            }
        }
    };
}
