//! An allocation the system refuses ends the run with a clean error (exit status 1) that names
//! the request and the address-space limit, instead of the standard library's abort (SIGABRT,
//! a core dump): the memory estimates refuse what will not fit before anything large is
//! allocated, but an estimate is not a guarantee (fragmentation, a tight `ulimit -v`, a limit
//! lowered while running), and a scripted caller must be able to tell "too big" from a crash.
//! The binary only: the library and the Python module keep the default.

use std::alloc::{GlobalAlloc, Layout, System};

/// The system allocator, ending the process cleanly where it returns null.
pub struct CleanOom;

// SAFETY: every call goes to `System` with the caller's arguments; a null result never returns.
unsafe impl GlobalAlloc for CleanOom {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract is passed on unchanged.
        checked(unsafe { System.alloc(layout) }, layout.size())
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as above.
        checked(unsafe { System.alloc_zeroed(layout) }, layout.size())
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: as above.
        checked(unsafe { System.realloc(ptr, layout, new_size) }, new_size)
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: as above.
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// `p`, or (where null) the error message and `_exit(1)`. Nothing here allocates: the message
/// is put together on the stack and written with write(2). The run's temporaries stay (their
/// names carry the dead process id, and the next run into the folder removes them).
fn checked(p: *mut u8, size: usize) -> *mut u8 {
    if !p.is_null() {
        return p;
    }
    let mut msg = Message::default();
    msg.push(b"error: out of memory: the system refused ");
    msg.mib(size as u64);
    msg.push(b" more");
    if let Some(limit) = address_space_limit() {
        msg.push(b" (address-space limit `ulimit -v`: ");
        msg.mib(limit);
        msg.push(b")");
    }
    msg.push(b"; lower the resolution, the mesh's size, --texels or the frame count, or allow more memory\n");
    // SAFETY: writes the message's initialised bytes to stderr, then ends the process without
    // running anything more (no destructor or atexit handler that could allocate).
    unsafe {
        libc::write(2, msg.buf.as_ptr().cast(), msg.len);
        libc::_exit(1)
    }
}

/// A message built without allocating.
struct Message {
    buf: [u8; 256],
    len: usize,
}

impl Default for Message {
    fn default() -> Self {
        Message {
            buf: [0; 256],
            len: 0,
        }
    }
}

impl Message {
    fn push(&mut self, s: &[u8]) {
        let n = s.len().min(self.buf.len() - self.len);
        self.buf[self.len..self.len + n].copy_from_slice(&s[..n]);
        self.len += n;
    }

    /// `bytes` in MiB, rounded up (`1 MiB` for less).
    fn mib(&mut self, bytes: u64) {
        let mut n = bytes.div_ceil(1 << 20).max(1);
        let mut digits = [0u8; 20];
        let mut k = digits.len();
        while n > 0 || k == digits.len() {
            k -= 1;
            digits[k] = b'0' + (n % 10) as u8;
            n /= 10;
        }
        self.push(&digits[k..]);
        self.push(b" MiB");
    }
}

/// The `ulimit -v` limit in bytes, where one is set.
fn address_space_limit() -> Option<u64> {
    let mut lim = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: `lim` is a writable rlimit; getrlimit(2) does not allocate.
    let ok = unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut lim) } == 0;
    (ok && lim.rlim_cur != libc::RLIM_INFINITY).then_some(lim.rlim_cur)
}
