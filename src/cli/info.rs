//! `zoovr info FILE [--json]`.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use serde_json::{json, Value};

use zoovr::io::{self, ReadOptions};
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
    let v = describe(&mesh, steps.len());
    if args.json {
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        print_text(&args.file, &v);
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

fn describe(mesh: &Mesh, timesteps: usize) -> Value {
    json!({
        "cells3d": mesh.cells.len(),
        "cells_by_type": mesh.source.cells_by_type,
        "ignored_cells": mesh.source.ignored_cells,
        "points": mesh.points.len(),
        "bounds": mesh.bounds(),
        "arrays": arrays_json(mesh),
        "timesteps": timesteps,
    })
}

fn print_text(file: &std::path::Path, v: &Value) {
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
