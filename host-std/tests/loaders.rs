//! Bad files never panic: valid EXR, Radiance HDR, PNG and TGA files, truncated and with bytes
//! flipped (proptest), decode to `Ok` or a clean error — never a panic — and no single
//! allocation made while decoding exceeds what the file could hold (decoded RGB of 1000× the
//! file's size or 64 MB, the loader's own bound, plus the decoders' fixed buffers).

use host_std::light::image_file::load_bytes;
use proptest::prelude::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;

struct PeakAlloc;

thread_local! {
    static ARMED: Cell<bool> = const { Cell::new(false) };
    static PEAK: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for PeakAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if ARMED.with(|a| a.get()) {
            PEAK.with(|p| p.set(p.get().max(layout.size())));
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if ARMED.with(|a| a.get()) {
            PEAK.with(|p| p.set(p.get().max(new_size)));
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: PeakAlloc = PeakAlloc;

/// The valid files, made once per test binary.
fn valid_files() -> &'static [(&'static str, Vec<u8>)] {
    static FILES: std::sync::OnceLock<Vec<(&'static str, Vec<u8>)>> = std::sync::OnceLock::new();
    FILES.get_or_init(make_files)
}

fn make_files() -> Vec<(&'static str, Vec<u8>)> {
    let (w, h) = (32u32, 16u32);
    let tmp = tempfile::Builder::new().prefix("ppis-loaders-").tempdir().unwrap();
    let dir = tmp.path();
    let exr_path = dir.join("a.exr");
    exr::prelude::write_rgb_file(&exr_path, w as usize, h as usize, |x, y| (x as f32 * 0.1, y as f32, 0.5f32)).unwrap();
    let exr = std::fs::read(&exr_path).unwrap();
    let rgb: Vec<f32> = (0..w * h).flat_map(|i| [(i % 7) as f32, 0.25, (i % 3) as f32 * 4.0]).collect();
    let image = image::Rgb32FImage::from_raw(w, h, rgb).unwrap();
    let mut hdr = Vec::new();
    image::DynamicImage::ImageRgb32F(image.clone())
        .write_to(&mut std::io::Cursor::new(&mut hdr), image::ImageFormat::Hdr)
        .unwrap();
    let encode = |format| {
        let mut out = Vec::new();
        image::DynamicImage::ImageRgb32F(image.clone())
            .to_rgb8()
            .write_to(&mut std::io::Cursor::new(&mut out), format)
            .unwrap();
        out
    };
    let (png, tga) = (encode(image::ImageFormat::Png), encode(image::ImageFormat::Tga));
    vec![("x.exr", exr), ("x.hdr", hdr), ("x.png", png), ("x.tga", tga)]
}

/// Decodes `bytes` as `name`; returns the decoder's largest single allocation, or the panic.
fn decode(name: &str, bytes: &[u8]) -> Result<usize, String> {
    PEAK.with(|p| p.set(0));
    ARMED.with(|a| a.set(true));
    let outcome = std::panic::catch_unwind(|| {
        if let Ok(image) = load_bytes(Path::new(name), bytes) {
            assert!(image.width > 0 && image.height > 0 && image.texels.len() == image.width * image.height);
            assert!(image.texels.iter().all(|t| t.iter().all(|c| c.is_finite() && *c >= 0.0)));
        }
    });
    ARMED.with(|a| a.set(false));
    match outcome {
        Ok(()) => Ok(PEAK.with(|p| p.get())),
        Err(e) => Err(e
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default()),
    }
}

/// What a decoder may allocate at once for a file of `len` bytes.
fn allowed(len: usize) -> usize {
    (1000 * len).max(64 << 20) + (16 << 20)
}

#[test]
fn valid_files_load() {
    for (name, bytes) in valid_files() {
        let image = load_bytes(Path::new(name), bytes).unwrap();
        assert_eq!((image.width, image.height), (32, 16), "{name}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 600, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn mutated_files_never_panic(kind in 0usize..4, cut in 0.0f64..1.0, flips in proptest::collection::vec((0.0f64..1.0, any::<u8>()), 0..8)) {
        let files = valid_files();
        let (name, original) = &files[kind];
        let mut bytes = original.clone();
        // Truncate to a random length (sometimes keep it whole), then flip random bytes.
        if cut < 0.7 {
            bytes.truncate((cut / 0.7 * original.len() as f64) as usize);
        }
        for (at, value) in &flips {
            if !bytes.is_empty() {
                let i = ((at * bytes.len() as f64) as usize).min(bytes.len() - 1);
                bytes[i] ^= value;
            }
        }
        let peak = decode(name, &bytes).map_err(|panic| TestCaseError::fail(format!("{name}: panicked: {panic}")))?;
        prop_assert!(peak <= allowed(bytes.len()), "{}: allocated {} bytes at once for a {}-byte file", name, peak, bytes.len());
    }
}

#[test]
fn headers_claiming_huge_images_are_refused_before_allocating() {
    // Radiance HDR: a text header claiming 30000×15000, a few bytes of data.
    let mut hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 15000 +X 30000\n".to_vec();
    hdr.extend_from_slice(&[2, 2, 0, 16, 1, 2, 3, 4]);
    // OpenEXR: the valid file with its dataWindow patched to 30000×15000.
    let mut exr = valid_files()[0].1.clone();
    let key = b"dataWindow\0box2i\0";
    let at = exr.windows(key.len()).position(|w| w == key).expect("dataWindow attribute") + key.len() + 4;
    exr[at + 8..at + 12].copy_from_slice(&29_999i32.to_le_bytes());
    exr[at + 12..at + 16].copy_from_slice(&14_999i32.to_le_bytes());
    for (name, bytes) in [("huge.hdr", hdr), ("huge.exr", exr)] {
        let err = load_bytes(Path::new(name), &bytes).expect_err(name);
        assert!(err.to_string().contains(name), "{err}");
        let peak = decode(name, &bytes).expect("no panic");
        assert!(peak <= allowed(bytes.len()), "{name}: {peak} bytes at once");
    }
}
