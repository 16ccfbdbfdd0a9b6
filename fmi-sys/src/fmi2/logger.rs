//! The importer's logger callback: [`fmi2_sys_logger`], a C shim (`csrc/logger.c`) that
//! formats the FMU's printf-style message and hands the text to a Rust [`LogReceiver`].
//!
//! An FMU's format string is not trusted: C cannot tell how many arguments a variadic
//! call passed, so the shim formats one conversion at a time and refuses what could write
//! to or read arbitrary memory. A format with `%n`, a `*` width or precision, a positional
//! `%1$` argument or a wide `%ls` / `%lc` is not formatted (the message says so and shows
//! the format); a `%s` argument is read only if it points to readable memory (checked with
//! `process_vm_readv`, which fails instead of faulting) outside the importer's program
//! image, else `<unreadable string>` or `<string in the importer's memory>` stands in its
//! place. Messages are cut at 4 KiB, categories and instance names at 255 bytes.
//!
//! The component environment of the callbacks is a [`LogEnvironment`]: its first field is
//! the Rust function the shim calls, so no Rust symbol is exported by name.
//!
//! ```
//! use fmi_sys::fmi2::logger::{LogEnvironment, LogMessage, LogReceiver};
//! use std::sync::Mutex;
//!
//! #[derive(Default)]
//! struct Messages(Mutex<Vec<String>>);
//! impl LogReceiver for Messages {
//!     fn receive(&self, m: &LogMessage<'_>) {
//!         self.0.lock().unwrap().push(format!("{} [{}] {}", m.instance_name, m.category, m.message));
//!     }
//! }
//! let environment = Box::new(LogEnvironment::new(Messages::default()));
//! let callbacks = environment.callbacks();
//! // what an FMU does with them (its strings live outside the importer's program image)
//! let logger = callbacks.logger.unwrap();
//! let name = std::ffi::CString::new("v_x").unwrap();
//! unsafe { logger(callbacks.component_environment, c"plant".as_ptr(), 3, c"logStatusError".as_ptr(), c"%s = %.3f".as_ptr(), name.as_ptr(), 0.35f64) };
//! assert_eq!(environment.receiver().0.lock().unwrap()[0], "plant [logStatusError] v_x = 0.350");
//! ```

use super::*;
use std::ffi::{c_char, c_void, CStr};

extern "C" {
    /// The logger callback (C-variadic, `csrc/logger.c`). Its component environment must
    /// be null or point to a [`LogEnvironment`].
    pub fn fmi2_sys_logger(
        env: fmi2ComponentEnvironment,
        instance_name: fmi2String,
        status: fmi2Status,
        category: fmi2String,
        message: fmi2String,
        ...
    );
}

/// One formatted message.
#[derive(Clone, Copy, Debug)]
pub struct LogMessage<'a> {
    /// The instance name the FMU passed (lossy UTF-8).
    pub instance_name: &'a str,
    /// The status the FMU passed, as it passed it (any `int`).
    pub status: fmi2Status,
    /// The category.
    pub category: &'a str,
    /// The formatted message.
    pub message: &'a str,
}

/// Who receives the formatted messages of the instances whose environment is a
/// [`LogEnvironment`] of it. Called on the thread that logs, inside the FMU's call: an
/// importer that runs instances on several threads makes its receiver thread-safe. A
/// panic in `receive` is caught (it never unwinds into the FMU); the message is then lost.
pub trait LogReceiver {
    /// Takes one message.
    fn receive(&self, message: &LogMessage<'_>);
}

type Receive = unsafe extern "C" fn(*const c_void, *const c_char, fmi2Status, *const c_char, *const c_char);

/// The component environment of an instance: the function the C shim calls, then the
/// receiver. It must stay at one address while an instance logs to it (box it).
#[repr(C)]
pub struct LogEnvironment<R: LogReceiver> {
    receive: Receive,
    receiver: R,
}

impl<R: LogReceiver + Default> Default for LogEnvironment<R> {
    fn default() -> Self {
        LogEnvironment::new(R::default())
    }
}

impl<R: LogReceiver + std::fmt::Debug> std::fmt::Debug for LogEnvironment<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.receiver.fmt(f)
    }
}

impl<R: LogReceiver> std::ops::Deref for LogEnvironment<R> {
    type Target = R;
    fn deref(&self) -> &R {
        &self.receiver
    }
}

impl<R: LogReceiver> LogEnvironment<R> {
    /// An environment whose messages go to `receiver`.
    pub fn new(receiver: R) -> Self {
        LogEnvironment { receive: receive::<R>, receiver }
    }

    /// The receiver.
    pub fn receiver(&self) -> &R {
        &self.receiver
    }

    /// This environment's address, the `componentEnvironment` of the callbacks.
    pub fn as_environment(&self) -> fmi2ComponentEnvironment {
        self as *const Self as fmi2ComponentEnvironment
    }

    /// The callbacks of an instance whose messages go here: the logger shim and the
    /// guarded calloc and free ([`super::guard`]). Valid while `self` stays where it is.
    pub fn callbacks(&self) -> Fmi2CallbackFunctions {
        Fmi2CallbackFunctions {
            logger: Some(fmi2_sys_logger),
            allocate_memory: Some(super::guard::allocate),
            free_memory: Some(super::guard::release),
            step_finished: None,
            component_environment: self.as_environment(),
        }
    }
}

/// What the C shim calls: `env` is the [`LogEnvironment<R>`] it was given, the strings are
/// the shim's own NUL-terminated copies.
unsafe extern "C" fn receive<R: LogReceiver>(
    env: *const c_void,
    instance_name: *const c_char,
    status: fmi2Status,
    category: *const c_char,
    message: *const c_char,
) {
    if env.is_null() {
        return;
    }
    let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let text = |p: *const c_char| {
            if p.is_null() {
                std::borrow::Cow::Borrowed("")
            } else {
                // SAFETY: the shim's NUL-terminated buffers, alive during this call.
                unsafe { CStr::from_ptr(p) }.to_string_lossy()
            }
        };
        // SAFETY: the callbacks of a LogEnvironment<R> carry its address (see `callbacks`).
        let environment = unsafe { &*(env as *const LogEnvironment<R>) };
        let (name, category, message) = (text(instance_name), text(category), text(message));
        environment.receiver.receive(&LogMessage {
            instance_name: &name,
            status,
            category: &category,
            message: &message,
        });
    }));
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    #[derive(Default)]
    struct Kept(Mutex<Vec<(i32, String, String)>>);
    impl LogReceiver for Kept {
        fn receive(&self, m: &LogMessage<'_>) {
            self.0.lock().unwrap().push((m.status, m.category.to_owned(), m.message.to_owned()));
        }
    }

    fn log(env: &LogEnvironment<Kept>) -> Vec<(i32, String, String)> {
        std::mem::take(&mut *env.receiver().0.lock().unwrap())
    }

    /// printf's own output for the same conversions (glibc), a %n refused, a NULL %s.
    #[test]
    fn the_shim_formats_like_printf_and_refuses_writes_to_memory() {
        let env = Box::new(LogEnvironment::<Kept>::default());
        let cb = env.callbacks();
        let logger = cb.logger.unwrap();
        // an FMU's string lives outside the importer's image: on the heap here
        let ab = std::ffi::CString::new("ab").unwrap();
        unsafe {
            logger(
                cb.component_environment,
                c"i".as_ptr(),
                1,
                c"cat".as_ptr(),
                c"%d|%5.2f|%-4s|%x|%%".as_ptr(),
                42,
                1.23456f64,
                ab.as_ptr(),
                255u32,
            );
            // a string in the importer's own constants is not shown
            logger(cb.component_environment, c"i".as_ptr(), 1, c"cat".as_ptr(), c"%s".as_ptr(), c"secret".as_ptr());
            logger(
                cb.component_environment,
                c"i".as_ptr(),
                3,
                c"cat".as_ptr(),
                c"%s%n".as_ptr(),
                c"x".as_ptr(),
                std::ptr::null_mut::<i32>(),
            );
            logger(
                cb.component_environment,
                c"i".as_ptr(),
                0,
                c"cat".as_ptr(),
                c"%s".as_ptr(),
                std::ptr::null::<c_char>(),
            );
        }
        let got = log(&env);
        assert_eq!(got[0], (1, "cat".into(), "42| 1.23|ab  |ff|%".into()));
        assert_eq!(got[1].2, "<string in the importer's memory>");
        assert_eq!(got[2].2, "[log message not formatted: its format contains %n, which writes to memory] %s%n");
        assert_eq!(got[3].2, "(null)");
    }

    /// A null environment is ignored, not dereferenced.
    #[test]
    fn a_null_environment_loses_the_message_without_crashing() {
        unsafe {
            fmi2_sys_logger(std::ptr::null_mut(), c"i".as_ptr(), 0, c"c".as_ptr(), c"%s".as_ptr(), c"m".as_ptr())
        };
    }

    /// A receiver that panics does not unwind into the caller.
    #[test]
    fn a_panicking_receiver_does_not_unwind_into_the_fmu() {
        struct Panics;
        impl LogReceiver for Panics {
            fn receive(&self, _: &LogMessage<'_>) {
                panic!("receiver panics");
            }
        }
        let env = Box::new(LogEnvironment::new(Panics));
        let cb = env.callbacks();
        unsafe {
            cb.logger.unwrap()(cb.component_environment, c"i".as_ptr(), 0, c"c".as_ptr(), c"%s".as_ptr(), c"m".as_ptr())
        };
    }
}
