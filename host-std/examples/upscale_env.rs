//! Writes a lat-long EXR upscaled (nearest) from another, for measuring big-map preprocessing:
//! `cargo run --release -p host-std --example upscale_env -- in.exr out.exr 4096`
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (input, output, width): (&str, &str, usize) = (&args[1], &args[2], args[3].parse().unwrap());
    let image = host_std::light::image_file::load(std::path::Path::new(input)).unwrap();
    let height = width / 2;
    exr::prelude::write_rgb_file(output, width, height, |x, y| {
        let t = image.texels[(y * image.height / height) * image.width + x * image.width / width];
        (t[0], t[1], t[2])
    })
    .unwrap();
}
