//! The isosurface stages of [`super::iso`] (`shaders/iso_vertex.wgsl`,
//! the segment's files, the volume's files, the glue that defines the
//! stage's `volume(l, s0, s1)`, and `shaders/iso.wgsl`): one per volume,
//! `--mode iso` (no volume), exact-frag's closed-form walk (by segment
//! thickness and Gauss rule) and each table mode, whose `volume` looks up
//! each sub-segment with its centred scalars offset into the table's terms
//! ([`super::iso::IsoParams::table_offset`]).

use crate::gpu::{Binding, StageDesc};

use super::exact_frag::{IntegralStages, THIN_CONSTANTS};
use super::iso::IsoVertex;

macro_rules! iso_stage {
    ($name:literal, [$($file:literal),*], $glue:literal, $bindings:expr) => {
        iso_stage!($name, [$($file),*], $glue, $bindings, &[])
    };
    ($name:literal, [$($file:literal),*], $glue:literal, $bindings:expr, $constants:expr) => {
        StageDesc {
            name: $name,
            fragment: "fs_iso",
            wgsl: concat!(
                include_str!("../../../shaders/iso_vertex.wgsl"),
                include_str!("../../../shaders/segment_view.wgsl"),
                include_str!("../../../shaders/segment.wgsl"),
                $(include_str!(concat!("../../../shaders/", $file)),)*
                $glue,
                include_str!("../../../shaders/iso.wgsl"),
            ),
            vertex: IsoVertex::LAYOUT,
            bindings: $bindings,
            constants: $constants,
        }
    };
}

const INTEGRAL_BINDINGS: &[Binding] = &[
    Binding::Uniform,
    Binding::Storage,
    Binding::Storage,
    Binding::Uniform,
    Binding::Storage,
];

/// `--mode iso`: no volume (the integral's bindings are bound, unused).
pub static ISO_STAGE: StageDesc = iso_stage!(
    "iso.wgsl",
    ["integral.wgsl", "iso_split.wgsl"],
    "\nfn volume(l: f32, sf: f32, sb: f32) -> vec4<f32> {\n    return vec4<f32>(0.0);\n}\n",
    INTEGRAL_BINDINGS
);

/// The isosurface stage with exact-frag's volume, as `name` with the
/// integral's `constants`: one walk over nodes and crossings
/// (`shaders/iso_walk.wgsl`).
macro_rules! iso_exact_frag_stage {
    ($name:literal, $constants:expr) => {
        iso_stage!(
            $name,
            ["integral.wgsl", "iso_walk.wgsl"],
            "",
            INTEGRAL_BINDINGS,
            $constants
        )
    };
}

/// `--iso` with `exact-frag`: the closed-form integral, walked over the
/// transfer function's nodes and the crossings together.
pub static ISO_EXACT_FRAG_STAGE: StageDesc = iso_exact_frag_stage!("iso.wgsl+exact_frag", &[]);

/// `--iso` with `exact-frag`, by segment thickness and Gauss rule (as
/// [`super::exact_frag::EXACT_FRAG_STAGES`]).
pub static ISO_EXACT_FRAG_STAGES: IntegralStages = IntegralStages {
    full: &ISO_EXACT_FRAG_STAGE,
    thin: [
        &iso_exact_frag_stage!("iso.wgsl+exact_frag+thin4", THIN_CONSTANTS[0]),
        &iso_exact_frag_stage!("iso.wgsl+exact_frag+thin5", THIN_CONSTANTS[1]),
        &iso_exact_frag_stage!("iso.wgsl+exact_frag+thin6", THIN_CONSTANTS[2]),
    ],
};

/// A table mode's isosurface stage, `name`, with the table's own file:
/// its `volume` looks up each sub-segment with its centred scalars offset
/// into the table's terms ([`super::iso::IsoParams::table_offset`]).
macro_rules! iso_table_stage {
    ($name:literal, $table:literal) => {
        iso_stage!(
            $name,
            ["preint.wgsl", $table, "iso_split.wgsl"],
            "\nfn volume(l: f32, sf: f32, sb: f32) -> vec4<f32> {\n    return preint_segment(sf + iso.table_offset, sb + iso.table_offset, l);\n}\n",
            &[
                Binding::Uniform,
                Binding::Table,
                Binding::Uniform,
                Binding::Uniform,
                Binding::Storage
            ]
        )
    };
}

/// `--iso` with `preint3d`.
pub static ISO_PREINT3D_STAGE: StageDesc = iso_table_stage!("iso.wgsl+preint3d", "preint3d.wgsl");

/// `--iso` with `preint2d`.
pub static ISO_PREINT2D_STAGE: StageDesc = iso_table_stage!("iso.wgsl+preint2d", "preint2d.wgsl");

/// `--iso` with `preint2d-cyl`.
pub static ISO_PREINT2D_CYL_STAGE: StageDesc =
    iso_table_stage!("iso.wgsl+preint2d_cyl", "preint2d_cyl.wgsl");
