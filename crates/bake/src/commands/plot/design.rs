//! A colour design beside its targets ([`DesignPlot`]): one column per target row (its
//! angle), the target swatch on top and each designed stack's swatch below it, labelled
//! with its ΔE2000.

use super::*;

/// One row of swatches: a label, a colour per column (linear sRGB, D65, a perfect
/// reflector = 1) and, for a designed stack, its ΔE2000 per column.
#[derive(Clone, Debug)]
pub struct SwatchRow {
    /// Label at the left.
    pub label: String,
    /// Per column: the colour.
    pub colours: Vec<[f64; 3]>,
    /// Per column: ΔE2000 to the target (None for the target row).
    pub delta_e: Option<Vec<f64>>,
}

/// Target swatches over designed ones, per target row.
#[derive(Clone, Debug)]
pub struct DesignPlot {
    /// Title.
    pub title: String,
    /// Per column: the target row's angle, degrees.
    pub angles_deg: Vec<f64>,
    /// The rows: the targets first, then each designed stack.
    pub rows: Vec<SwatchRow>,
    /// Factor applied to the linear colours before clipping.
    pub exposure: f64,
}

/// Swatch size and spacing, pixels.
const CELL: (i32, i32) = (96, 72);
const GAP: i32 = 10;
const LABEL_W: i32 = 110;

impl Figure for DesignPlot {
    fn size(&self) -> (u32, u32) {
        let cols = self.angles_deg.len() as i32;
        let rows = self.rows.len() as i32;
        (
            (LABEL_W + cols * (CELL.0 + GAP) + 30).max(480) as u32,
            (40 + 30 + rows * (CELL.1 + 28)) as u32,
        )
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        _format: ImageFormat,
    ) -> DrawResult<DB> {
        let area = root.titled(&self.title, ("sans-serif", 17))?;
        let font = |size: i32, h: HPos, v: VPos| {
            ("sans-serif", size)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(h, v))
        };
        let top = 30;
        for (c, a) in self.angles_deg.iter().enumerate() {
            let x = LABEL_W + c as i32 * (CELL.0 + GAP);
            area.draw(&Text::new(
                format!("{a}°"),
                (x + CELL.0 / 2, top - 6),
                font(15, HPos::Center, VPos::Bottom),
            ))?;
        }
        for (r, row) in self.rows.iter().enumerate() {
            let (label, colours, de) = (&row.label, &row.colours, &row.delta_e);
            let y = top + r as i32 * (CELL.1 + 28);
            area.draw(&Text::new(
                label.clone(),
                (LABEL_W - 12, y + CELL.1 / 2),
                font(15, HPos::Right, VPos::Center),
            ))?;
            for (c, colour) in colours.iter().enumerate() {
                let x = LABEL_W + c as i32 * (CELL.0 + GAP);
                let rgb = srgb8(colour.map(|v| v * self.exposure));
                area.draw(&Rectangle::new(
                    [(x, y), (x + CELL.0, y + CELL.1)],
                    rgb.filled(),
                ))?;
                if let Some(de) = de {
                    area.draw(&Text::new(
                        format!("ΔE {:.2}", de[c]),
                        (x + CELL.0 / 2, y + CELL.1 + 4),
                        font(13, HPos::Center, VPos::Top),
                    ))?;
                }
            }
        }
        Ok(())
    }
}
