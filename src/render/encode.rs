//! Picture encoding from packed RGB8 buffers to file bytes: PNG, and animated GIF with one
//! global palette (the renders' most frequent exact colours, so flat colours stay exact)
//! where each frame after the first stores only the changed rectangle, unchanged pixels
//! transparent — stick-figure clips compress to a small fraction of full frames.

use super::error::RenderError;
use std::collections::HashMap;

/// Palette index reserved for "unchanged since the previous frame".
const TRANSPARENT: u8 = 255;

/// PNG bytes of a `w`×`h` RGB8 picture.
pub(crate) fn encode_png(rgb: &[u8], w: u32, h: u32) -> Result<Vec<u8>, RenderError> {
    let enc_err = |e: png::EncodingError| RenderError::Encode(e.to_string());
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().map_err(enc_err)?;
        writer.write_image_data(rgb).map_err(enc_err)?;
        writer.finish().map_err(enc_err)?;
    }
    Ok(out)
}

/// Up to 255 colours and a fast RGB → index mapping.
pub(crate) struct Palette {
    colors: Vec<[u8; 3]>,
    exact: HashMap<[u8; 3], u8>,
    /// Nearest palette index for every 5-bit-per-channel colour.
    nearest: Vec<u8>,
}

impl Palette {
    /// The 255 most frequent colours of the sample pictures.
    pub fn from_samples(samples: &[Vec<u8>]) -> Palette {
        let mut counts: HashMap<[u8; 3], u64> = HashMap::new();
        for rgb in samples {
            for px in rgb.chunks_exact(3) {
                *counts.entry([px[0], px[1], px[2]]).or_default() += 1;
            }
        }
        let mut by_count: Vec<([u8; 3], u64)> = counts.into_iter().collect();
        // Ties broken by colour so the palette is deterministic.
        by_count.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        let mut colors: Vec<[u8; 3]> = by_count.into_iter().take(255).map(|(c, _)| c).collect();
        if colors.is_empty() {
            colors.push([255, 255, 255]);
        }
        let exact = colors
            .iter()
            .enumerate()
            .map(|(i, c)| (*c, i as u8))
            .collect();
        let nearest = (0..32 * 32 * 32)
            .map(|key: usize| {
                let c =
                    [(key >> 10) & 31, (key >> 5) & 31, key & 31].map(|v| (v * 255 / 31) as i32);
                let dist =
                    |p: &[u8; 3]| (0..3).map(|k| (i32::from(p[k]) - c[k]).pow(2)).sum::<i32>();
                (0..colors.len())
                    .min_by_key(|&i| dist(&colors[i]))
                    .unwrap_or(0) as u8
            })
            .collect();
        Palette {
            colors,
            exact,
            nearest,
        }
    }

    /// Palette index of one colour.
    fn index(&self, c: [u8; 3]) -> u8 {
        match self.exact.get(&c) {
            Some(i) => *i,
            None => {
                let key = (usize::from(c[0] >> 3) << 10)
                    | (usize::from(c[1] >> 3) << 5)
                    | usize::from(c[2] >> 3);
                self.nearest[key]
            }
        }
    }

    /// Palette indices of a packed RGB8 picture.
    pub fn quantise(&self, rgb: &[u8]) -> Vec<u8> {
        let mut out = Vec::with_capacity(rgb.len() / 3);
        // Renders are mostly long runs of one colour: remember the last lookup.
        let mut last = ([0u8; 3], self.index([0, 0, 0]));
        for px in rgb.chunks_exact(3) {
            let c = [px[0], px[1], px[2]];
            if c != last.0 {
                last = (c, self.index(c));
            }
            out.push(last.1);
        }
        out
    }

    /// The 256-entry GIF colour table (the transparent slot is white).
    fn table(&self) -> Vec<u8> {
        let mut t: Vec<u8> = self.colors.iter().flatten().copied().collect();
        t.resize(256 * 3, 255);
        t
    }
}

/// Streams indexed frames into an in-memory animated GIF.
pub(crate) struct GifWriter {
    enc: gif::Encoder<Vec<u8>>,
    w: u16,
    h: u16,
    prev: Option<Vec<u8>>,
}

fn gif_err(e: impl std::fmt::Display) -> RenderError {
    RenderError::Encode(e.to_string())
}

impl GifWriter {
    /// A looping GIF of `w`×`h` pixels with `palette` as its global colour table.
    pub fn new(w: u32, h: u32, palette: &Palette) -> Result<GifWriter, RenderError> {
        let too_big = || RenderError::BadOption(format!("GIF size {w}x{h} exceeds 65535"));
        let (w, h) = (
            u16::try_from(w).map_err(|_| too_big())?,
            u16::try_from(h).map_err(|_| too_big())?,
        );
        let mut enc = gif::Encoder::new(Vec::new(), w, h, &palette.table()).map_err(gif_err)?;
        enc.set_repeat(gif::Repeat::Infinite).map_err(gif_err)?;
        Ok(GifWriter {
            enc,
            w,
            h,
            prev: None,
        })
    }

    /// Appends a frame of palette indices shown for `delay_cs` hundredths of a second.
    pub fn push(&mut self, indices: Vec<u8>, delay_cs: u16) -> Result<(), RenderError> {
        let (w, h) = (usize::from(self.w), usize::from(self.h));
        let mut frame = match &self.prev {
            None => gif::Frame {
                width: self.w,
                height: self.h,
                buffer: indices.as_slice().into(),
                ..Default::default()
            },
            Some(prev) => changed_part(prev, &indices, w, h),
        };
        frame.delay = delay_cs;
        frame.dispose = gif::DisposalMethod::Keep;
        self.enc.write_frame(&frame).map_err(gif_err)?;
        self.prev = Some(indices);
        Ok(())
    }

    /// The finished file's bytes.
    pub fn finish(self) -> Result<Vec<u8>, RenderError> {
        self.enc.into_inner().map_err(gif_err)
    }
}

/// The smallest rectangle holding every changed pixel, unchanged ones transparent
/// (a single transparent pixel when nothing changed, which keeps the frame's timing).
fn changed_part(prev: &[u8], cur: &[u8], w: usize, h: usize) -> gif::Frame<'static> {
    let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0, 0);
    for y in 0..h {
        let row = y * w;
        for x in 0..w {
            if prev[row + x] != cur[row + x] {
                (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
            }
        }
    }
    if x0 > x1 {
        (x0, y0, x1, y1) = (0, 0, 0, 0);
    }
    let mut buffer = Vec::with_capacity((x1 - x0 + 1) * (y1 - y0 + 1));
    for y in y0..=y1 {
        for x in x0..=x1 {
            let i = y * w + x;
            buffer.push(if prev[i] == cur[i] {
                TRANSPARENT
            } else {
                cur[i]
            });
        }
    }
    gif::Frame {
        left: x0 as u16,
        top: y0 as u16,
        width: (x1 - x0 + 1) as u16,
        height: (y1 - y0 + 1) as u16,
        transparent: Some(TRANSPARENT),
        buffer: buffer.into(),
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn palette_keeps_frequent_colours_exact_and_maps_others_near() {
        let mut rgb = Vec::new();
        for _ in 0..100 {
            rgb.extend_from_slice(&[255, 255, 255]);
        }
        rgb.extend_from_slice(&[20, 70, 170]);
        let p = Palette::from_samples(&[rgb.clone()]);
        let q = p.quantise(&rgb);
        assert_eq!(p.colors[usize::from(q[0])], [255, 255, 255]);
        assert_eq!(p.colors[usize::from(q[100])], [20, 70, 170]);
        // An unseen near-white maps to white.
        assert_eq!(
            p.colors[usize::from(p.quantise(&[250, 252, 251])[0])],
            [255, 255, 255]
        );
    }

    #[test]
    fn changed_part_is_the_bounding_box_of_changes() {
        let prev = vec![0u8; 20];
        let mut cur = prev.clone();
        cur[5 + 1] = 7; // (x=1, y=1) in a 5×4 picture
        cur[10 + 3] = 9; // (x=3, y=2)
        let f = changed_part(&prev, &cur, 5, 4);
        assert_eq!((f.left, f.top, f.width, f.height), (1, 1, 3, 2));
        assert_eq!(&f.buffer[..], &[7, 255, 255, 255, 255, 9]);
        let same = changed_part(&prev, &prev, 5, 4);
        assert_eq!(
            (same.width, same.height, &same.buffer[..]),
            (1, 1, &[255u8][..])
        );
    }

    #[test]
    fn gif_frames_decode_back_to_the_pictures_pushed() {
        // Three colours; frames change a moving block, then one frame repeats exactly.
        let (w, h) = (12usize, 7usize);
        let colours = [[255u8, 255, 255], [20, 70, 170], [210, 0, 150]];
        let picture = |k: usize| -> Vec<u8> {
            (0..w * h)
                .flat_map(|i| {
                    let (x, y) = (i % w, i / w);
                    let c = if x / 3 == k % 4 && y > 1 {
                        1
                    } else if x == 11 - k {
                        2
                    } else {
                        0
                    };
                    colours[c]
                })
                .collect()
        };
        let frames: Vec<Vec<u8>> = [0, 1, 2, 2, 3].into_iter().map(picture).collect();
        let palette = Palette::from_samples(&frames);
        let mut writer = GifWriter::new(w as u32, h as u32, &palette).unwrap();
        for f in &frames {
            writer.push(palette.quantise(f), 5).unwrap();
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.gif");
        std::fs::write(&path, writer.finish().unwrap()).unwrap();
        let g = crate::render::test_util::decode_gif(&path);
        assert_eq!((g.w, g.h, g.delays.len()), (w, h, 5));
        for (k, f) in frames.iter().enumerate() {
            assert_eq!(&g.frames[k], f, "frame {k} differs after decoding");
        }
    }
}
