//! Test helpers for reading pictures back: GIF decoding with frame compositing (so each
//! frame is the full picture a viewer shows), PNG decoding, and pixel queries by colour.

use plotters::style::RGBColor;
use std::path::Path;

/// A decoded GIF: size, per-frame delays and the composited RGB picture after each frame.
pub(crate) struct DecodedGif {
    /// Width in pixels.
    pub w: usize,
    /// Height in pixels.
    pub h: usize,
    /// Each frame's delay in hundredths of a second.
    pub delays: Vec<u16>,
    /// The packed RGB picture shown after each frame.
    pub frames: Vec<Vec<u8>>,
}

/// Decodes and composites every frame of a GIF file.
pub(crate) fn decode_gif(path: &Path) -> DecodedGif {
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::Indexed);
    let mut dec = opts.read_info(std::fs::File::open(path).unwrap()).unwrap();
    let (w, h) = (usize::from(dec.width()), usize::from(dec.height()));
    let palette = dec.global_palette().unwrap().to_vec();
    let mut canvas = vec![0u8; w * h * 3];
    let (mut delays, mut frames) = (Vec::new(), Vec::new());
    while let Some(f) = dec.read_next_frame().unwrap() {
        for y in 0..usize::from(f.height) {
            for x in 0..usize::from(f.width) {
                let i = f.buffer[y * usize::from(f.width) + x];
                if Some(i) == f.transparent {
                    continue;
                }
                let at = ((y + usize::from(f.top)) * w + x + usize::from(f.left)) * 3;
                canvas[at..at + 3]
                    .copy_from_slice(&palette[usize::from(i) * 3..usize::from(i) * 3 + 3]);
            }
        }
        delays.push(f.delay);
        frames.push(canvas.clone());
    }
    DecodedGif {
        w,
        h,
        delays,
        frames,
    }
}

/// Decodes an RGB8 PNG file: width, height, packed pixels.
pub(crate) fn decode_png(path: &Path) -> (usize, usize, Vec<u8>) {
    let dec = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buf.truncate(info.buffer_size());
    (info.width as usize, info.height as usize, buf)
}

/// Pixel positions (x, y) of an exact colour in a packed RGB picture of width `w`.
pub(crate) fn pixels_of(rgb: &[u8], w: usize, c: RGBColor) -> Vec<(usize, usize)> {
    rgb.chunks_exact(3)
        .enumerate()
        .filter(|(_, p)| p[0] == c.0 && p[1] == c.1 && p[2] == c.2)
        .map(|(i, _)| (i % w, i / w))
        .collect()
}

pub(crate) fn mean(v: &[(usize, usize)]) -> (f32, f32) {
    let n = v.len().max(1) as f32;
    (
        v.iter().map(|p| p.0 as f32).sum::<f32>() / n,
        v.iter().map(|p| p.1 as f32).sum::<f32>() / n,
    )
}

/// Number of entries in a directory.
pub(crate) fn dir_entries(dir: &Path) -> usize {
    std::fs::read_dir(dir).unwrap().count()
}
