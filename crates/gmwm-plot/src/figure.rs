//! A figure: panels on a grid at a size in pixels, rendered to SVG or PNG.

use crate::chart::{draw, Panel};
use crate::PlotError;
use plotters::prelude::{BitMapBackend, IntoDrawingArea, SVGBackend};
use std::path::Path;

/// Largest side of a figure, pixels.
pub const MAX_SIDE: u32 = 20_000;
/// Largest area of a figure, pixels (a 40-megapixel PNG buffer is 120 MB).
pub const MAX_PIXELS: u64 = 40_000_000;

/// Whether a `width` x `height` figure is within [`MAX_SIDE`] and [`MAX_PIXELS`].
pub fn within_limits(width: u32, height: u32) -> bool {
    width <= MAX_SIDE && height <= MAX_SIDE && u64::from(width) * u64::from(height) <= MAX_PIXELS
}

/// Output format of a figure file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// Scalable vector graphics (text stays text).
    Svg,
    /// Portable network graphics (8-bit RGB).
    Png,
}

impl ImageFormat {
    /// The format of a file name: `.svg` or `.png` (case-insensitive).
    ///
    /// # Errors
    /// [`PlotError::Format`] for any other extension.
    pub fn of(path: &Path) -> Result<Self, PlotError> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("svg") => Ok(Self::Svg),
            Some("png") => Ok(Self::Png),
            _ => Err(PlotError::Format(path.display().to_string())),
        }
    }
}

/// Panels on a grid, ready to render.
///
/// ```
/// use gmwm_plot::{Figure, Mark, Panel, PanelKind, Series};
/// let panel = Panel {
///     title: "white noise".into(),
///     x_label: "scale τ (s)".into(),
///     y_label: "wavelet variance".into(),
///     kind: PanelKind::LogLog(vec![Series::new(Mark::LinePoints, &[1.0, 2.0, 4.0], &[1.0, 0.5, 0.25])]),
/// };
/// let svg = Figure::new(vec![panel], (1, 1), (640, 400)).svg().unwrap();
/// assert!(svg.starts_with("<svg"));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Panels, row-major.
    pub panels: Vec<Panel>,
    /// Rows and columns of the grid.
    pub grid: (usize, usize),
    /// Width and height in pixels.
    pub size: (u32, u32),
}

impl Figure {
    /// A figure of `panels` on a `grid` (rows, columns) at `size` (width, height) pixels.
    pub fn new(panels: Vec<Panel>, grid: (usize, usize), size: (u32, u32)) -> Self {
        Self { panels, grid, size }
    }

    /// At another size.
    pub fn with_size(mut self, size: (u32, u32)) -> Self {
        self.size = size;
        self
    }

    /// The SVG document.
    ///
    /// # Errors
    /// [`PlotError::Draw`] if plotters fails (a size too small for the axes).
    pub fn svg(&self) -> Result<String, PlotError> {
        self.check_size()?;
        let mut out = String::new();
        {
            let root = SVGBackend::with_string(&mut out, self.size).into_drawing_area();
            draw(root, &self.panels, self.grid)?;
        }
        Ok(out)
    }

    /// The PNG file's bytes (8-bit RGB, text in the embedded DejaVu Sans).
    ///
    /// # Errors
    /// As [`Figure::svg`]; [`PlotError::Png`] if encoding fails.
    pub fn png(&self) -> Result<Vec<u8>, PlotError> {
        self.check_size()?;
        let (w, h) = self.size;
        let mut pixels = vec![0u8; w as usize * h as usize * 3];
        {
            let root = BitMapBackend::with_buffer(&mut pixels, self.size).into_drawing_area();
            draw(root, &self.panels, self.grid)?;
        }
        let mut out = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut out, w, h);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            let mut writer = encoder
                .write_header()
                .map_err(|e| PlotError::Png(e.to_string()))?;
            writer
                .write_image_data(&pixels)
                .map_err(|e| PlotError::Png(e.to_string()))?;
        }
        Ok(out)
    }

    /// Writes the figure to `path` in the format its extension names (`.svg`, `.png`).
    ///
    /// # Errors
    /// [`PlotError::Format`] for another extension, [`PlotError::Io`] naming the file.
    pub fn save(&self, path: &Path) -> Result<(), PlotError> {
        let bytes = match ImageFormat::of(path)? {
            ImageFormat::Svg => self.svg()?.into_bytes(),
            ImageFormat::Png => self.png()?,
        };
        // atomically: an interrupted run leaves the previous figure or none
        gmwm::write_atomic(path, &bytes).map_err(|e| match e {
            gmwm::ReadError::Io { source, .. } => PlotError::Io {
                path: path.display().to_string(),
                source,
            },
            other => PlotError::Io {
                path: path.display().to_string(),
                source: std::io::Error::other(other.to_string()),
            },
        })
    }

    /// Every panel's legend entries.
    pub fn legend(&self) -> Vec<String> {
        self.panels.iter().flat_map(Panel::legend).collect()
    }

    fn check_size(&self) -> Result<(), PlotError> {
        let (w, h) = self.size;
        let (rows, cols) = self.grid;
        let (min_w, min_h) = (320 * cols.max(1) as u32, 240 * rows.max(1) as u32);
        if w < min_w || h < min_h || !within_limits(w, h) {
            return Err(PlotError::Size {
                width: w,
                height: h,
                min_width: min_w,
                min_height: min_h,
            });
        }
        Ok(())
    }
}
