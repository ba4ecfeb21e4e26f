//! Fuzz target: the `.vti` reader must return an image or an error for any bytes, never
//! panic; an image it returns holds `width × height` values, and written back as `Float32`
//! (as `cylvol render --depth` writes) reads back to the same values rounded to `f32`.
#![no_main]

use cylvol::io::vti;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let Ok(image) = vti::read_point_scalars(data) else {
        return;
    };
    assert_eq!(
        image.values.len() as u64,
        image.width as u64 * image.height as u64
    );
    let rounded: Vec<f32> = image.values.iter().map(|&v| v as f32).collect();
    let mut bytes = Vec::new();
    if vti::write_point_scalars(&mut bytes, image.width, image.height, &image.name, &rounded)
        .is_err()
    {
        // Only an empty image is refused, and no image read is empty.
        panic!("a {}x{} image read but not written", image.width, image.height);
    }
    let back = vti::read_point_scalars(&bytes).expect("our own file reads back");
    assert_eq!((back.width, back.height), (image.width, image.height));
    assert_eq!(back.name, image.name);
    let bits = |v: &[f64]| v.iter().map(|x| (*x as f32).to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&back.values), bits(&image.values));
});
