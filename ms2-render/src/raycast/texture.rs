//! Textures on the CPU: bilinear, repeating lookups in linear RGB, as the raster path's sampler.

use crate::TextureData;
use parry3d::math::Vec3;
use std::sync::OnceLock;

/// A texture decoded to linear RGB.
pub(crate) struct CpuTexture {
    width: usize,
    height: usize,
    texels: Vec<Vec3>,
}

fn srgb_to_linear_table() -> &'static [f32; 256] {
    static TABLE: OnceLock<[f32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| {
        std::array::from_fn(|k| {
            let c = k as f32 / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        })
    })
}

impl CpuTexture {
    /// Decodes a validated texture.
    pub(crate) fn new(data: &TextureData) -> CpuTexture {
        let table = srgb_to_linear_table();
        CpuTexture {
            width: data.width as usize,
            height: data.height as usize,
            texels: data
                .rgba8_srgb
                .chunks_exact(4)
                .map(|t| {
                    Vec3::new(
                        table[t[0] as usize],
                        table[t[1] as usize],
                        table[t[2] as usize],
                    )
                })
                .collect(),
        }
    }

    /// Bilinear sample at `uv` (u right, v down, repeating), linear RGB.
    pub(crate) fn sample_linear(&self, uv: [f32; 2]) -> Vec3 {
        let x = uv[0] * self.width as f32 - 0.5;
        let y = uv[1] * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let wrap = |v: f32, n: usize| (v as i64).rem_euclid(n as i64) as usize;
        let texel = |dx: f32, dy: f32| {
            self.texels[wrap(y0 + dy, self.height) * self.width + wrap(x0 + dx, self.width)]
        };
        let top = texel(0.0, 0.0) * (1.0 - fx) + texel(1.0, 0.0) * fx;
        let bottom = texel(0.0, 1.0) * (1.0 - fx) + texel(1.0, 1.0) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}
