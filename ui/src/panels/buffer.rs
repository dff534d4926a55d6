//! The buffer viewer: a buffer as of the current pass, read back from the replay, shown as
//! rows of a type the frame gives it (the indirect-argument records it feeds, or the WGSL type
//! of a variable bound to it, from naga's reflection), or as raw bytes in hex. Only the rows on
//! screen are formatted, so a buffer of millions of rows scrolls as fast as a small one.

use egui_extras::{Column, TableBuilder};

use crate::model::{BufferView, LayoutChoice};
use crate::state::View;
use crate::worker::MAX_BUFFER_READ;

const ROW_HEIGHT: f32 = 18.0;
/// Bytes per raw row.
const HEX_ROW: usize = 16;

/// The text of each column of row `row` read as `choice`: the row index, its byte offset,
/// then one value per field; `None` past the bytes at hand.
pub fn typed_row(bytes: &[u8], choice: &LayoutChoice, row: u64) -> Option<Vec<String>> {
    let start = choice
        .base
        .checked_add(row.checked_mul(choice.layout.stride)?)?;
    let start_index = usize::try_from(start).ok()?;
    let tail = bytes.get(start_index..)?;
    let end = usize::try_from(choice.layout.stride).ok()?.min(tail.len());
    let data = &tail[..end];
    let mut cells = vec![row.to_string(), format!("0x{start:x}")];
    cells.extend(
        choice
            .layout
            .fields
            .iter()
            .map(|f| f.read(data).unwrap_or_else(|| "-".into())),
    );
    Some(cells)
}

/// Rows of `choice` that start within `len` bytes.
pub fn typed_rows(len: u64, choice: &LayoutChoice) -> u64 {
    len.saturating_sub(choice.base)
        .div_ceil(choice.layout.stride.max(1))
}

/// Raw row `row`: offset, 16 bytes in hex, and those bytes as ASCII.
pub fn hex_row(bytes: &[u8], row: usize) -> [String; 3] {
    let start = row.saturating_mul(HEX_ROW).min(bytes.len());
    let chunk = &bytes[start..(start + HEX_ROW).min(bytes.len())];
    let hex: Vec<String> = chunk.iter().map(|b| format!("{b:02x}")).collect();
    let ascii: String = chunk
        .iter()
        .map(|&b| {
            if b.is_ascii_graphic() || b == b' ' {
                char::from(b)
            } else {
                '.'
            }
        })
        .collect();
    [format!("0x{start:08x}"), hex.join(" "), ascii]
}

fn header(app: &mut View, ui: &mut egui::Ui, view: &BufferView) {
    let model = app.model.clone();
    ui.horizontal_wrapped(|ui| {
        let current = app.selection.buffer;
        let name = current.map_or("(none)", |r| model.resources[r].name.as_str());
        let mut pick = None;
        egui::ComboBox::from_id_salt("buffer")
            .selected_text(name)
            .width(200.0)
            .show_ui(ui, |ui| {
                for (i, r) in model.resources.iter().enumerate() {
                    if r.buffer.is_some()
                        && ui.selectable_label(current == Some(i), &r.name).clicked()
                    {
                        pick = Some(i);
                    }
                }
            });
        ui.label(format!("{} bytes", view.size));
        let shown = app
            .selection
            .buffer_layout
            .and_then(|l| view.layouts.get(l))
            .map_or("raw bytes (hex)".to_owned(), |c| {
                format!("{} ({})", c.layout.type_name, c.source)
            });
        egui::ComboBox::from_id_salt("buffer layout")
            .selected_text(shown)
            .width(320.0)
            .show_ui(ui, |ui| {
                for (i, c) in view.layouts.iter().enumerate() {
                    let text = format!("{} ({})", c.layout.type_name, c.source);
                    ui.selectable_value(&mut app.selection.buffer_layout, Some(i), text);
                }
                ui.selectable_value(&mut app.selection.buffer_layout, None, "raw bytes (hex)");
            });
        if let Some(i) = pick {
            app.open_resource(i);
        }
    });
    for use_ in &view.indirect {
        ui.weak(format!("indirect arguments for {use_}"));
    }
    if view.size > MAX_BUFFER_READ {
        ui.weak(format!(
            "showing the first {} MiB of {} bytes",
            MAX_BUFFER_READ >> 20,
            view.size
        ));
    }
}

fn typed_table(ui: &mut egui::Ui, bytes: &[u8], choice: &LayoutChoice) {
    let rows = typed_rows(bytes.len() as u64, choice);
    let fields = &choice.layout.fields;
    // The body scrolls within what the panel has left below the header, so the last row
    // can be reached however small the panel is.
    let height = (ui.available_height() - ROW_HEIGHT).max(ROW_HEIGHT);
    TableBuilder::new(ui)
        .id_salt("buffer rows")
        .striped(true)
        .min_scrolled_height(0.0)
        .max_scroll_height(height)
        .resizable(true)
        .column(Column::auto().at_least(40.0))
        .column(Column::auto().at_least(60.0))
        .columns(Column::auto().at_least(50.0), fields.len())
        .header(ROW_HEIGHT, |mut h| {
            h.col(|ui| {
                ui.strong("#");
            });
            h.col(|ui| {
                ui.strong("offset");
            });
            for f in fields {
                h.col(|ui| {
                    ui.strong(if f.name.is_empty() { "value" } else { &f.name });
                });
            }
        })
        .body(|body| {
            let count = usize::try_from(rows).unwrap_or(usize::MAX);
            body.rows(ROW_HEIGHT, count, |mut row| {
                let cells = typed_row(bytes, choice, row.index() as u64).unwrap_or_default();
                for text in cells {
                    row.col(|ui| {
                        ui.add(egui::Label::new(egui::RichText::new(text).monospace()).extend());
                    });
                }
            });
        });
}

fn hex_table(ui: &mut egui::Ui, bytes: &[u8]) {
    // The body scrolls within what the panel has left below the header, so the last row
    // can be reached however small the panel is.
    let height = (ui.available_height() - ROW_HEIGHT).max(ROW_HEIGHT);
    TableBuilder::new(ui)
        .id_salt("buffer hex")
        .striped(true)
        .min_scrolled_height(0.0)
        .max_scroll_height(height)
        .column(Column::auto().at_least(90.0))
        .column(Column::auto().at_least(380.0))
        .column(Column::remainder())
        .header(ROW_HEIGHT, |mut h| {
            for t in ["offset", "bytes", "ascii"] {
                h.col(|ui| {
                    ui.strong(t);
                });
            }
        })
        .body(|body| {
            body.rows(ROW_HEIGHT, bytes.len().div_ceil(HEX_ROW), |mut row| {
                for text in hex_row(bytes, row.index()) {
                    row.col(|ui| {
                        ui.add(egui::Label::new(egui::RichText::new(text).monospace()).extend());
                    });
                }
            });
        });
}

pub fn ui(app: &mut View, ui: &mut egui::Ui) {
    let model = app.model.clone();
    let Some(view) = app
        .selection
        .buffer
        .and_then(|r| model.resources[r].buffer.as_ref())
    else {
        ui.label("Open a buffer from the resource table.");
        return;
    };
    header(app, ui, view);
    let Some(((pass, index), bytes)) = app.buffer_bytes.clone() else {
        ui.spinner();
        return;
    };
    if index != view.plan_index {
        ui.spinner();
        return;
    }
    if pass != app.selection.pass {
        ui.weak(format!(
            "as of {} (replaying to the current pass)",
            model.passes.get(pass).map_or("?", |p| p.name.as_str())
        ));
    }
    match app
        .selection
        .buffer_layout
        .and_then(|l| view.layouts.get(l))
    {
        Some(choice) => typed_table(ui, &bytes, choice),
        None => hex_table(ui, &bytes),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::BufferLayout;

    #[test]
    fn rows_start_at_the_base_and_step_by_the_stride() {
        let choice = LayoutChoice {
            source: "test".into(),
            base: 4,
            layout: BufferLayout::dispatch_indirect(),
        };
        let bytes: Vec<u8> = (0u32..8).flat_map(|v| v.to_le_bytes()).collect();
        assert_eq!(typed_rows(bytes.len() as u64, &choice), 3);
        assert_eq!(
            typed_row(&bytes, &choice, 1).unwrap(),
            ["1", "0x10", "4", "5", "6"]
        );
        // The last row is cut short by the end of the buffer.
        assert_eq!(typed_row(&bytes, &choice, 2).unwrap()[2..], ["7", "-", "-"]);
        assert!(typed_row(&bytes, &choice, 3).is_none());
        let [offset, hex, ascii] = hex_row(b"framelab\x00\x01", 0);
        assert_eq!(offset, "0x00000000");
        assert_eq!(hex, "66 72 61 6d 65 6c 61 62 00 01");
        assert_eq!(ascii, "framelab..");
    }
}
