//! Turning rendered images into window pixels: aspect-preserving scaling into the window's
//! `0x00RRGGBB` framebuffer, and segmentation ids as colours (ms2-render's
//! [`ms2_render::segmentation_color`]).

/// Colour of the window outside the image (letterbox bars), `0x00RRGGBB`.
pub const LETTERBOX: u32 = 0x0020_2020;

/// RGB (3 bytes per pixel, row-major) of a segmentation image.
pub fn segmentation_rgb(ids: &[u32]) -> Vec<u8> {
    ids.iter()
        .flat_map(|&id| ms2_render::segmentation_color(id))
        .collect()
}

/// Draws the RGB image `rgb` (`width`×`height`, 3 bytes per pixel, row-major) into `dst`
/// (`dst_width`×`dst_height` pixels of `0x00RRGGBB`), scaled with nearest-neighbour sampling
/// to the largest size that keeps its aspect ratio, centred, with [`LETTERBOX`] around it.
///
/// # Panics
/// Never for consistent sizes; `rgb` shorter than `width * height * 3` or `dst` shorter than
/// `dst_width * dst_height` draws what fits (callers pass matching sizes).
pub fn blit_fit(
    rgb: &[u8],
    width: u32,
    height: u32,
    dst: &mut [u32],
    dst_width: u32,
    dst_height: u32,
) {
    dst.fill(LETTERBOX);
    if width == 0 || height == 0 || dst_width == 0 || dst_height == 0 {
        return;
    }
    let (w, h) = (width as u64, height as u64);
    let (dw, dh) = (dst_width as u64, dst_height as u64);
    // Largest scaled size with the source's aspect ratio.
    let (sw, sh) = if dw * h <= dh * w {
        (dw, (dw * h / w).max(1))
    } else {
        ((dh * w / h).max(1), dh)
    };
    let (ox, oy) = ((dw - sw) / 2, (dh - sh) / 2);
    for y in 0..sh {
        let src_y = (y * h / sh).min(h - 1);
        let row = ((oy + y) * dw) as usize;
        for x in 0..sw {
            let src_x = (x * w / sw).min(w - 1);
            let s = ((src_y * w + src_x) * 3) as usize;
            let (Some(px), Some(out)) = (rgb.get(s..s + 3), dst.get_mut(row + (ox + x) as usize))
            else {
                continue;
            };
            *out = (px[0] as u32) << 16 | (px[1] as u32) << 8 | px[2] as u32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_size_copies_pixels() {
        let rgb = [255, 0, 0, 0, 255, 0, 0, 0, 255, 1, 2, 3];
        let mut dst = [0u32; 4];
        blit_fit(&rgb, 2, 2, &mut dst, 2, 2);
        assert_eq!(dst, [0xff0000, 0x00ff00, 0x0000ff, 0x010203]);
    }

    #[test]
    fn wide_window_letterboxes_left_and_right() {
        // A 1×1 red image into a 4×2 window: scaled to 2×2, centred, bars on both sides.
        let mut dst = [0u32; 8];
        blit_fit(&[255, 0, 0], 1, 1, &mut dst, 4, 2);
        let red = 0xff0000;
        assert_eq!(
            dst,
            [LETTERBOX, red, red, LETTERBOX, LETTERBOX, red, red, LETTERBOX]
        );
    }

    #[test]
    fn segmentation_colours_are_distinct_and_background_black() {
        let rgb = segmentation_rgb(&[0, 1, 2]);
        assert_eq!(&rgb[0..3], &[0, 0, 0]);
        assert_ne!(&rgb[3..6], &rgb[6..9]);
        assert!(rgb[3..9].iter().all(|&c| c >= 0x40));
    }
}
