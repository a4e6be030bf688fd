//! The charts' canvas (the accuracy study's work-precision plot, the Campbell diagram): an RGB
//! frame that `embedded-graphics` draws into, written as a PNG by the `png` crate.

use embedded_graphics::pixelcolor::Rgb888;
use embedded_graphics::prelude::*;

/// A white RGB frame of `width` × `height` pixels.
pub struct Canvas {
    width: u32,
    height: u32,
    rgb: Vec<u8>,
}

impl Canvas {
    /// A white frame.
    pub fn new(width: u32, height: u32) -> Canvas {
        Canvas {
            width,
            height,
            rgb: vec![255; 3 * width as usize * height as usize],
        }
    }

    /// The frame as PNG bytes (8-bit RGB).
    pub fn png(&self) -> Vec<u8> {
        let mut out = Vec::new();
        let mut encoder = png::Encoder::new(&mut out, self.width, self.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        // into memory, with the data's size matching the header: no error can arise
        let written = encoder
            .write_header()
            .and_then(|mut w| w.write_image_data(&self.rgb));
        debug_assert!(written.is_ok(), "{written:?}");
        out
    }
}

impl OriginDimensions for Canvas {
    fn size(&self) -> Size {
        Size::new(self.width, self.height)
    }
}

impl DrawTarget for Canvas {
    type Color = Rgb888;
    type Error = std::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(
        &mut self,
        pixels: I,
    ) -> Result<(), Self::Error> {
        for Pixel(p, c) in pixels {
            if p.x >= 0 && p.y >= 0 && (p.x as u32) < self.width && (p.y as u32) < self.height {
                let i = 3 * (p.y as usize * self.width as usize + p.x as usize);
                self.rgb[i..i + 3].copy_from_slice(&[c.r(), c.g(), c.b()]);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use embedded_graphics::primitives::{PrimitiveStyle, Rectangle};

    #[test]
    fn a_drawn_pixel_reads_back_from_the_png() {
        let mut c = Canvas::new(3, 2);
        let _ = Rectangle::new(Point::new(1, 1), Size::new(1, 1))
            .into_styled(PrimitiveStyle::with_fill(Rgb888::new(200, 10, 20)))
            .draw(&mut c);
        let bytes = c.png();
        let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
            .read_info()
            .unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (3, 2));
        assert_eq!(&buf[3 * 4..3 * 4 + 3], &[200, 10, 20]);
        assert_eq!(&buf[..3], &[255, 255, 255]);
    }
}
