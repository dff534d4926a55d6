//! The resource table: every resource with kind, format, size, mips, layers, bytes, heap and
//! offset, first and last pass, and what it aliases with; filtered, sorted by any column; a
//! click opens a texture in the viewer.

use egui_extras::{Column, TableBuilder};

use crate::model::{Inspection, Resource};
use crate::state::View;

const HEADERS: [&str; 10] = [
    "name", "kind", "format", "size", "mips", "layers", "bytes", "heap", "passes", "aliases",
];

fn pass_name(m: &Inspection, p: Option<usize>) -> String {
    p.and_then(|p| m.passes.get(p))
        .map_or("-".to_owned(), |p| p.name.clone())
}

fn size(r: &Resource) -> String {
    if r.kind == "buffer" {
        "-".to_owned()
    } else if r.depth > 1 {
        format!("{}x{}x{}", r.width, r.height, r.depth)
    } else {
        format!("{}x{}", r.width, r.height)
    }
}

fn cells(m: &Inspection, r: &Resource) -> [String; 10] {
    let heap = match r.offset {
        Some(o) => format!("{} @ {o:#x}", r.heap),
        None => r.heap.clone(),
    };
    [
        r.name.clone(),
        r.kind.clone(),
        r.format.clone(),
        size(r),
        r.mips.to_string(),
        r.layers.to_string(),
        r.bytes.to_string(),
        heap,
        format!(
            "{} .. {}",
            pass_name(m, r.first_pass),
            pass_name(m, r.last_pass)
        ),
        r.aliases.join(", "),
    ]
}

/// Row order: filtered by name, format or kind, sorted by the chosen column.
pub fn rows(m: &Inspection, filter: &str, (column, ascending): (usize, bool)) -> Vec<usize> {
    let f = filter.to_lowercase();
    let mut rows: Vec<usize> = (0..m.resources.len())
        .filter(|&i| {
            let r = &m.resources[i];
            f.is_empty()
                || r.name.to_lowercase().contains(&f)
                || r.format.to_lowercase().contains(&f)
                || r.kind.contains(&f)
        })
        .collect();
    rows.sort_by(|&a, &b| {
        let (ra, rb) = (&m.resources[a], &m.resources[b]);
        let order = match column {
            3 => (ra.width as u64 * ra.height as u64).cmp(&(rb.width as u64 * rb.height as u64)),
            4 => ra.mips.cmp(&rb.mips),
            5 => ra.layers.cmp(&rb.layers),
            6 => ra.bytes.cmp(&rb.bytes),
            8 => ra.first_pass.cmp(&rb.first_pass),
            c => cells(m, ra)[c.min(9)].cmp(&cells(m, rb)[c.min(9)]),
        };
        let order = order.then(a.cmp(&b));
        if ascending { order } else { order.reverse() }
    });
    rows
}

pub fn ui(app: &mut View, ui: &mut egui::Ui) {
    ui.horizontal(|ui| {
        ui.label("filter");
        ui.add(
            egui::TextEdit::singleline(&mut app.selection.resource_filter)
                .id_salt("resource filter")
                .desired_width(200.0),
        );
    });
    let model = app.model.clone();
    let order = rows(&model, &app.selection.resource_filter, app.selection.sort);
    let mut open = None;
    let mut sort = app.selection.sort;
    let height = (ui.available_height() - 20.0).max(20.0);
    TableBuilder::new(ui)
        .id_salt("resources")
        .striped(true)
        .min_scrolled_height(0.0)
        .max_scroll_height(height)
        .resizable(true)
        .columns(Column::auto().at_least(40.0), HEADERS.len())
        .header(18.0, |mut header| {
            for (c, h) in HEADERS.iter().enumerate() {
                header.col(|ui| {
                    let mark = match sort {
                        (s, true) if s == c => " ^",
                        (s, false) if s == c => " v",
                        _ => "",
                    };
                    if ui.button(format!("{h}{mark}")).clicked() {
                        sort = (c, if sort.0 == c { !sort.1 } else { true });
                    }
                });
            }
        })
        .body(|body| {
            body.rows(18.0, order.len(), |mut row| {
                let i = order[row.index()];
                let r = &model.resources[i];
                for (c, text) in cells(&model, r).into_iter().enumerate() {
                    row.col(|ui| {
                        if c == 0 {
                            let selected = app.selection.resource == Some(i)
                                || app.selection.buffer == Some(i);
                            if ui.selectable_label(selected, text).clicked() {
                                open = Some(i);
                            }
                        } else {
                            ui.label(text);
                        }
                    });
                }
            });
        });
    app.selection.sort = sort;
    if let Some(i) = open {
        app.open_resource(i);
    }
}
