//! The ownership traits every handle type (`Model`, `Options`, `Map`) has:
//! it frees its C handle, held in its `ptr: NonNull<_>` field, when dropped,
//! and a cloneable one clones through its `try_clone`.

/// `owned_handle!(Type, free_fn)` implements Drop through the C free
/// function; `owned_handle!(Type, free_fn, clone: "what")` adds Clone
/// through `Type::try_clone`, whose error names "what".
macro_rules! owned_handle {
    ($ty:ident, $free:path) => {
        impl Drop for $ty {
            fn drop(&mut self) {
                // SAFETY: we own the handle; nothing else uses it once dropped.
                unsafe { $free(self.ptr.as_ptr()) }
            }
        }
    };
    ($ty:ident, $free:path, clone: $what:literal) => {
        owned_handle!($ty, $free);

        impl Clone for $ty {
            /// Panics only when memory runs out, as `Vec::clone` would; use
            /// `try_clone` to handle that.
            fn clone(&self) -> $ty {
                self.try_clone()
                    .unwrap_or_else(|e| panic!(concat!("cloning ", $what, " failed: {}"), e))
            }
        }
    };
}
