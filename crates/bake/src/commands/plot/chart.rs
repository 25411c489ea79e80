//! Swatch charts: film thickness rows × angle or film-index columns ([`ChartPlot`]).

use super::*;

/// What the columns of a swatch chart vary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChartColumns {
    /// Incidence angle in the ambient, degrees.
    Angle,
    /// The film's real index.
    FilmIor,
}

/// A swatch chart of film colours: one row per film thickness (increasing downwards),
/// one column per angle or film index, each swatch filled with the colour as sRGB (see
/// the module's colour conventions: clipped per channel, sRGB-encoded, × exposure).
#[derive(Clone, Debug)]
pub struct ChartPlot {
    /// Title.
    pub title: String,
    /// Row values: film thickness, nm, evenly spaced.
    pub thicknesses_nm: Vec<f64>,
    /// Column values.
    pub columns: Vec<f64>,
    /// What the columns are.
    pub column_kind: ChartColumns,
    /// Linear sRGB (D65, a perfect reflector = 1) per swatch, row-major.
    pub colours: Vec<[f64; 3]>,
    /// Factor applied to the linear colour before clipping.
    pub exposure: f64,
}

impl ChartPlot {
    fn cell_px(&self) -> (u32, u32) {
        let cols = self.columns.len().max(1) as u32;
        let rows = self.thicknesses_nm.len().max(1) as u32;
        ((900 / cols).clamp(48, 150), (900 / rows).clamp(4, 26))
    }
}

impl Figure for ChartPlot {
    fn size(&self) -> (u32, u32) {
        let (cw, rh) = self.cell_px();
        (
            (120 + cw * self.columns.len() as u32).max(640),
            150 + rh * self.thicknesses_nm.len() as u32,
        )
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        _format: ImageFormat,
    ) -> DrawResult<DB> {
        let area = root.titled(&self.title, ("sans-serif", 17))?;
        let (cw, _) = self.cell_px();
        let cols = self.columns.len();
        let d = &self.thicknesses_nm;
        let step = if d.len() > 1 { d[1] - d[0] } else { 1.0 };
        let (top, bottom) = (-(d[0] - step / 2.0), -(d[d.len() - 1] + step / 2.0));
        let width = (cw * cols as u32) as i32;
        let (w, _) = area.dim_in_pixel();
        let side = ((w as i32 - width - 90) / 2).max(10);
        let mut chart = ChartBuilder::on(&area)
            .margin_top(64)
            .margin_bottom(16)
            .margin_left(side)
            .margin_right(side)
            .y_label_area_size(72)
            .build_cartesian_2d(0.0..cols as f64, bottom..top)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .disable_y_mesh()
            .x_labels(0)
            .y_labels(16)
            .y_label_formatter(&|v| format!("{:.0}", -v + 0.0))
            .y_desc("film thickness d (nm)")
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .draw()?;
        let mut cells = Vec::with_capacity(self.colours.len());
        for (r, &t) in d.iter().enumerate() {
            for c in 0..cols {
                let colour = self.colours[r * cols + c].map(|v| v * self.exposure);
                cells.push(Rectangle::new(
                    [
                        (c as f64 + 0.03, -(t - step / 2.0)),
                        (c as f64 + 0.97, -(t + step / 2.0)),
                    ],
                    srgb8(colour).filled(),
                ));
            }
        }
        chart.draw_series(cells)?;
        let header = ("sans-serif", 15)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Bottom));
        for (c, v) in self.columns.iter().enumerate() {
            let (x, y) = chart.backend_coord(&(c as f64 + 0.5, top));
            let text = match self.column_kind {
                ChartColumns::Angle => format!("{v}°"),
                ChartColumns::FilmIor => format!("n = {v}"),
            };
            root.draw(&Text::new(text, (x, y - 6), header.clone()))?;
        }
        let (x0, y0) = chart.backend_coord(&(0.0, top));
        let (x1, _) = chart.backend_coord(&(cols as f64, top));
        let caption = match self.column_kind {
            ChartColumns::Angle => "angle of incidence θ (in the ambient)",
            ChartColumns::FilmIor => "film index n",
        };
        root.draw(&Text::new(
            caption,
            ((x0 + x1) / 2, y0 - 30),
            ("sans-serif", 16)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Center, VPos::Bottom)),
        ))?;
        Ok(())
    }
}
