//! `zoovr info FILE [--json]`: what a file holds (cells by kind, points,
//! bounds, arrays with types and ranges, time steps) and the structure and
//! quality facts of [`MeshReport`] (boundary faces, components, convexity,
//! inverted / degenerate cells, nonplanar faces, inverted consistent tets).
//! The JSON keys are a contract (docs/conventions.md, Conventions); the text output
//! prints the same values. `hidden_cells` and `duplicate_cells` count the
//! cells a `vtkGhostType` cell array flags (0 without one); the text output
//! prints them only when the array exists.

use std::path::PathBuf;

use anyhow::{Context as _, Result};
use clap::Args;
use serde_json::{json, Value};

use zoovr::io::{self, ReadOptions};
use zoovr::mesh::ghost::{cell_ghost_array, GhostCounts};
use zoovr::mesh::report::MeshReport;
use zoovr::mesh::Mesh;

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// The dataset or time collection to describe.
    pub file: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// PLOT3D solution file to attach to a PLOT3D grid.
    #[arg(long)]
    pub q: Option<PathBuf>,
}

pub fn run(args: &InfoArgs) -> Result<()> {
    let steps = io::read_series(&args.file)?;
    let opts = ReadOptions {
        q_file: args.q.clone(),
    };
    let mesh = io::read(&args.file, &opts)?;
    let v = describe(&mesh, steps.len()).with_context(|| format!("{}", args.file.display()))?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        print_text(&args.file, &v, cell_ghost_array(&mesh).is_some());
    }
    Ok(())
}

fn arrays_json(mesh: &Mesh) -> Vec<Value> {
    let mut out = Vec::new();
    for (assoc, arrays) in [("point", &mesh.point_data), ("cell", &mesh.cell_data)] {
        for a in arrays {
            let comp = if a.components == 1 { Some(0) } else { None };
            let range = a
                .range(comp)
                .map(|(lo, hi)| json!([lo, hi]))
                .unwrap_or(Value::Null);
            out.push(json!({
                "name": a.name,
                "association": assoc,
                "components": a.components,
                "type": a.vtk_type,
                "range": range,
            }));
        }
    }
    out
}

/// Finite JSON number or `null`.
fn num(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

pub(crate) fn describe(mesh: &Mesh, timesteps: usize) -> Result<Value> {
    let ghosts = GhostCounts::of(mesh)?;
    let r = MeshReport::compute(mesh);
    Ok(json!({
        "cells3d": mesh.cells.len(),
        "cells_by_type": mesh.source.cells_by_type,
        "ignored_cells": mesh.source.ignored_cells,
        "points": mesh.points.len(),
        "bounds": mesh.bounds(),
        "arrays": arrays_json(mesh),
        "timesteps": timesteps,
        "faces": r.faces,
        "boundary_faces": r.boundary_faces,
        "nonmanifold_faces": r.nonmanifold_faces,
        "components": r.components,
        "volume": num(r.volume),
        "hull_volume": num(r.hull_volume),
        "convexity": r.convexity.map_or(Value::Null, num),
        "inverted_cells": r.inverted_cells,
        "degenerate_cells": r.degenerate_cells,
        "repeated_index_cells": r.repeated_index_cells,
        "nonplanar_faces": r.nonplanar_faces,
        "max_nonplanarity": num(r.max_nonplanarity),
        "tets": r.tets,
        "inverted_tets": r.inverted_tets,
        "flat_tets": r.flat_tets,
        "coincident_points": r.coincident_points,
        "hidden_cells": ghosts.hidden,
        "duplicate_cells": ghosts.duplicate,
        "notes": mesh.source.notes,
    }))
}

fn print_text(file: &std::path::Path, v: &Value, ghost_array: bool) {
    println!("file:        {}", file.display());
    println!("cells (3D):  {}", v["cells3d"]);
    if let Some(m) = v["cells_by_type"].as_object() {
        for (k, n) in m {
            println!("  {k:<22} {n}");
        }
    }
    println!("points:      {}", v["points"]);
    println!("bounds:      {}", v["bounds"]);
    println!("time steps:  {}", v["timesteps"]);
    println!(
        "faces:       {} ({} boundary, {} non-manifold)",
        v["faces"], v["boundary_faces"], v["nonmanifold_faces"]
    );
    println!("components:  {}", v["components"]);
    println!(
        "convexity:   {} (volume {} / hull volume {})",
        v["convexity"], v["volume"], v["hull_volume"]
    );
    println!(
        "cells:       {} inverted, {} degenerate, {} with a repeated point",
        v["inverted_cells"], v["degenerate_cells"], v["repeated_index_cells"]
    );
    println!(
        "quad faces:  {} nonplanar (> 1e-3 of the face diagonal; max {})",
        v["nonplanar_faces"], v["max_nonplanarity"]
    );
    println!(
        "tets:        {} consistent, {} inverted after repair, {} flat",
        v["tets"], v["inverted_tets"], v["flat_tets"]
    );
    println!("ignored:     {} 0D-2D cells", v["ignored_cells"]);
    println!("coincident:  {} points", v["coincident_points"]);
    if ghost_array {
        println!(
            "ghost cells: {} hidden, {} duplicate (vtkGhostType; not drawn without --show-hidden)",
            v["hidden_cells"], v["duplicate_cells"]
        );
    }
    if let Some(notes) = v["notes"].as_array().filter(|n| !n.is_empty()) {
        println!("notes:");
        for n in notes {
            println!("  {}", n.as_str().unwrap_or(""));
        }
    }
    if let Some(arrs) = v["arrays"].as_array() {
        println!("arrays:");
        for a in arrs {
            println!(
                "  {:<5} {:<30} {} x {} range {}",
                a["association"].as_str().unwrap_or(""),
                a["name"].as_str().unwrap_or(""),
                a["type"].as_str().unwrap_or(""),
                a["components"],
                a["range"]
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use zoovr::generate::{ghost_grid, ring_grid, warped_hex_grid, zoo_grid, Warp};

    #[test]
    fn json_of_a_generated_grid() {
        let m = warped_hex_grid(3, &Warp::default());
        let v = describe(&m, 1).unwrap();
        assert_eq!(v["cells3d"], 27);
        assert_eq!(v["cells_by_type"]["hexahedron"], 27);
        assert_eq!(v["points"], 64);
        assert_eq!(v["boundary_faces"], 54);
        assert_eq!(v["faces"], 108);
        assert_eq!(v["components"], 1);
        assert_eq!(v["inverted_cells"], 0);
        assert_eq!(v["degenerate_cells"], 0);
        assert_eq!(v["inverted_tets"], 0);
        assert_eq!(v["nonmanifold_faces"], 0);
        assert_eq!(v["timesteps"], 1);
        assert!(v["nonplanar_faces"].as_u64().unwrap() > 0);
        let c = v["convexity"].as_f64().unwrap();
        // the warp bulges the boundary in and out: not convex
        assert!(c > 0.7 && c < 0.99, "{c}");
        let straight = describe(
            &warped_hex_grid(
                3,
                &Warp {
                    amplitude: 0.0,
                    seed: 1,
                },
            ),
            1,
        )
        .unwrap();
        let c = straight["convexity"].as_f64().unwrap();
        assert!((c - 1.0).abs() < 1e-12, "{c}");
        assert_eq!(straight["nonplanar_faces"], 0);
        let arr = &v["arrays"][0];
        assert_eq!(arr["name"], "f");
        assert_eq!(arr["association"], "point");
        assert_eq!(arr["type"], "Float32");
        let b = v["bounds"].as_array().unwrap();
        assert_eq!(b.len(), 6);
    }

    #[test]
    fn json_of_a_ring_and_a_zoo() {
        let v = describe(
            &ring_grid(
                6,
                &Warp {
                    amplitude: 0.0,
                    seed: 1,
                },
            ),
            1,
        )
        .unwrap();
        // 6x6x2 minus the 2x2x2 hole
        assert_eq!(v["cells3d"], 64);
        let c = v["convexity"].as_f64().unwrap();
        assert!((c - 32.0 / 36.0).abs() < 1e-12, "{c}");
        let z = describe(&zoo_grid(3, &Warp::default()), 1).unwrap();
        for k in ["hexahedron", "wedge", "pyramid", "tetra"] {
            assert!(z["cells_by_type"][k].as_u64().unwrap() > 0, "{k}");
        }
        assert_eq!(z["components"], 1);
        assert_eq!(z["inverted_tets"], 0);
    }

    #[test]
    fn json_counts_ghost_cells() {
        let v = describe(&warped_hex_grid(2, &Warp::default()), 1).unwrap();
        assert_eq!(
            (&v["hidden_cells"], &v["duplicate_cells"]),
            (&json!(0), &json!(0))
        );
        let mut m = ghost_grid(4, &Warp::default());
        let v = describe(&m, 1).unwrap();
        let c = GhostCounts::of(&m).unwrap();
        assert!(c.hidden > 0 && c.duplicate > 0);
        assert_eq!(v["hidden_cells"], c.hidden);
        assert_eq!(v["duplicate_cells"], c.duplicate);
        // every cell is still described
        assert_eq!(v["cells3d"], 64);
        m.cell_data[0].components = 2;
        let err = describe(&m, 1).unwrap_err().to_string();
        assert!(err.contains("vtkGhostType"), "{err}");
    }
}
