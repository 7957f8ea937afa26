//! openusd 0.6 panics on some corrupt files (an index out of range in the usdc reader). The
//! importer turns such a panic into an error naming the file: [`guarded`] catches it, and a
//! panic hook installed once keeps panics raised inside openusd off stderr (their message
//! goes into the error instead); every other panic reaches the previous hook unchanged.

use crate::error::UsdError;
use std::cell::RefCell;
use std::panic::{self, AssertUnwindSafe};
use std::path::Path;
use std::sync::Once;

thread_local! {
    /// The message of the last panic raised inside openusd on this thread.
    static LAST: RefCell<Option<String>> = const { RefCell::new(None) };
}

fn install_hook() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let previous = panic::take_hook();
        panic::set_hook(Box::new(move |info| {
            let inside_openusd = info.location().is_some_and(|l| l.file().contains("openusd"));
            if inside_openusd {
                let msg = info
                    .payload()
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| info.payload().downcast_ref::<String>().cloned())
                    .unwrap_or_default();
                let at = info
                    .location()
                    .map(|l| format!(" ({}:{})", l.file().rsplit("src/").next().unwrap_or(""), l.line()));
                LAST.with(|m| *m.borrow_mut() = Some(format!("{msg}{}", at.unwrap_or_default())));
            } else {
                previous(info);
            }
        }));
    });
}

/// Runs `f`; a panic inside it becomes `UsdError::Open` naming `file`.
pub fn guarded<T>(file: &Path, f: impl FnOnce() -> Result<T, UsdError>) -> Result<T, UsdError> {
    install_hook();
    match panic::catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => {
            let message = LAST.with(|m| m.borrow_mut().take()).unwrap_or_else(|| {
                payload
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| payload.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "unknown failure".into())
            });
            Err(UsdError::Open {
                file: file.to_owned(),
                message: format!("the file is corrupt: the USD reader failed: {message}"),
            })
        }
    }
}
