//! VTK XML UnstructuredGrid (`.vtu`) output and PVD time series for ParaView.
//!
//! [`write_vtu`] writes one mesh state: the points (the mesh coordinates or a given
//! deformed configuration), the cells (VTK_TRIANGLE or VTK_TETRA) and any number of point
//! (node) and cell (element) data arrays. [`PvdSeries`] writes one `.vtu` file per time
//! step and keeps a `.pvd` collection file listing them with their times, which ParaView
//! opens as a time series.
//!
//! File layout (VTK XML format version 1.0, `byte_order="LittleEndian"`,
//! `header_type="UInt64"`):
//!
//! * points: `Float64`, 3 components (z = 0 in 2D), array name `Points`;
//! * cells: `connectivity` and `offsets` as `Int64`, `types` as `UInt8`;
//! * [`DataArray::Scalar`]: `Float64`, 1 component;
//! * [`DataArray::Vector`]: `Float64`, 3 components (z = 0 in 2D);
//! * [`DataArray::SymTensor`]: `Float64`, the full 9-component tensor, row-major
//!   (`xx xy xz yx yy yz zx zy zz`; in 2D the z row and column are zero);
//! * [`DataArray::Int`]: `Int32`, 1 component.
//!
//! With [`VtuEncoding::RawBinary`] (the default) every array is stored in one
//! `<AppendedData encoding="raw">` block after an `_` marker: per array an 8-byte
//! little-endian byte count followed by the little-endian values; each `DataArray` element
//! gives its `offset` into that block. [`VtuEncoding::Ascii`] writes the values as text
//! inside the `DataArray` elements (larger, for debugging and tests). Values are written
//! as given: the writer does no unit conversion (SI units throughout pcdc-rs).
//!
//! ```no_run
//! use pcdc_mesh::vtu::{DataArray, PvdSeries};
//! # fn demo(mesh: &pcdc_mesh::Mesh<pcdc_mesh::Dim2>, u: &[f64], s: &[f64]) -> Result<(), pcdc_mesh::MeshError> {
//! let mut series = PvdSeries::new("out", "specimen")?;
//! series.write_step(
//!     0.0,
//!     mesh,
//!     None,
//!     &[DataArray::Vector { name: "displacement", values: u }],
//!     &[DataArray::SymTensor { name: "stress", values: s }],
//! )?;
//! # Ok(()) }
//! ```

use std::collections::HashSet;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::{Dim, Mesh, MeshError};

/// A named data array attached to the points (nodes) or cells (elements) of a `.vtu` file.
///
/// Point data has one tuple per mesh node, cell data one per element, in mesh order.
#[derive(Clone, Copy, Debug)]
pub enum DataArray<'a> {
    /// One `f64` per entity (written as a 1-component `Float64` array).
    Scalar {
        /// Array name shown in ParaView.
        name: &'a str,
        /// Values, one per entity.
        values: &'a [f64],
    },
    /// A vector per entity, stride `D` (written with 3 components, z = 0 in 2D).
    Vector {
        /// Array name shown in ParaView.
        name: &'a str,
        /// Components `x, y` (2D) or `x, y, z` (3D) per entity.
        values: &'a [f64],
    },
    /// A symmetric tensor per entity, stride `D::NSYM` (written as a full 9-component
    /// tensor).
    SymTensor {
        /// Array name shown in ParaView.
        name: &'a str,
        /// Components `xx, yy, xy` (2D) or `xx, yy, zz, xy, yz, xz` (3D) per entity.
        values: &'a [f64],
    },
    /// One `i32` per entity (written as a 1-component `Int32` array), e.g. group ids or
    /// flags.
    Int {
        /// Array name shown in ParaView.
        name: &'a str,
        /// Values, one per entity.
        values: &'a [i32],
    },
}

impl<'a> DataArray<'a> {
    /// The array name.
    pub fn name(&self) -> &'a str {
        match *self {
            DataArray::Scalar { name, .. }
            | DataArray::Vector { name, .. }
            | DataArray::SymTensor { name, .. }
            | DataArray::Int { name, .. } => name,
        }
    }

    /// Number of values per entity expected in the input for dimension `D`:
    /// 1 (scalar, int), `D` (vector) or `D::NSYM` (symmetric tensor).
    pub fn input_stride<D: Dim>(&self) -> usize {
        match self {
            DataArray::Scalar { .. } | DataArray::Int { .. } => 1,
            DataArray::Vector { .. } => D::D,
            DataArray::SymTensor { .. } => D::NSYM,
        }
    }

    /// Number of values in the input slice.
    pub fn len(&self) -> usize {
        match self {
            DataArray::Scalar { values, .. }
            | DataArray::Vector { values, .. }
            | DataArray::SymTensor { values, .. } => values.len(),
            DataArray::Int { values, .. } => values.len(),
        }
    }

    /// Whether the input slice is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// How the arrays of a `.vtu` file are encoded.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum VtuEncoding {
    /// Raw little-endian binary in an `<AppendedData encoding="raw">` block, each array
    /// preceded by its byte count as a `UInt64` (compact and fast; the default).
    #[default]
    RawBinary,
    /// Whitespace-separated text inside each `DataArray` (human-readable, larger).
    Ascii,
}

/// Writes `mesh` as a VTK XML UnstructuredGrid file with raw appended binary data.
///
/// * `points`: optional coordinates replacing the mesh coordinates (stride `D`, one
///   point per node, m), e.g. the deformed configuration.
/// * `point_data`: arrays with one tuple per node.
/// * `cell_data`: arrays with one tuple per element.
///
/// See the [module documentation](self) for the file layout.
///
/// # Errors
///
/// [`MeshError::Io`] with kind [`io::ErrorKind::InvalidInput`] and a message naming the
/// array if an array length does not match the node or element count, an array name is
/// empty or repeated within the point or cell data; [`MeshError::Io`] if the file cannot
/// be written. Nothing is written when the arrays are invalid.
pub fn write_vtu<D: Dim>(
    path: impl AsRef<Path>,
    mesh: &Mesh<D>,
    points: Option<&[f64]>,
    point_data: &[DataArray],
    cell_data: &[DataArray],
) -> Result<(), MeshError> {
    write_vtu_with(
        path,
        mesh,
        points,
        point_data,
        cell_data,
        VtuEncoding::RawBinary,
    )
}

/// Like [`write_vtu`] but with ASCII data ([`VtuEncoding::Ascii`]).
pub fn write_vtu_ascii<D: Dim>(
    path: impl AsRef<Path>,
    mesh: &Mesh<D>,
    points: Option<&[f64]>,
    point_data: &[DataArray],
    cell_data: &[DataArray],
) -> Result<(), MeshError> {
    write_vtu_with(
        path,
        mesh,
        points,
        point_data,
        cell_data,
        VtuEncoding::Ascii,
    )
}

/// Like [`write_vtu`] with an explicit [`VtuEncoding`].
pub fn write_vtu_with<D: Dim>(
    path: impl AsRef<Path>,
    mesh: &Mesh<D>,
    points: Option<&[f64]>,
    point_data: &[DataArray],
    cell_data: &[DataArray],
    encoding: VtuEncoding,
) -> Result<(), MeshError> {
    let path = path.as_ref();
    let io_err = |source| MeshError::Io {
        path: path.display().to_string(),
        source,
    };
    let grid = Grid::new(mesh, points, point_data, cell_data).map_err(io_err)?;
    let file = File::create(path).map_err(io_err)?;
    let mut w = BufWriter::new(file);
    grid.write(&mut w, encoding).map_err(io_err)?;
    w.flush().map_err(io_err)
}

/// Cells other than a mesh's elements, for [`write_cells_vtu`]: e.g. the line (2D) or
/// triangle (3D) channels of a flow network, or bolt segments.
#[derive(Clone, Copy, Debug)]
pub struct Cells<'a> {
    /// Point coordinates (m), stride `D`.
    pub points: &'a [f64],
    /// Point indices of every cell, stride `nodes_per_cell`.
    pub connectivity: &'a [u32],
    /// Points per cell.
    pub nodes_per_cell: usize,
    /// The VTK cell type ([`VTK_LINE`], [`VTK_TRIANGLE`], ...).
    pub cell_type: u8,
}

/// VTK cell type of a two-point line.
pub const VTK_LINE: u8 = 3;
/// VTK cell type of a three-point triangle.
pub const VTK_TRIANGLE: u8 = 5;

/// Writes `cells` as a VTK XML UnstructuredGrid (raw appended binary), with point data
/// (one tuple per point) and cell data (one per cell), validated as in [`write_vtu`]
/// (plus: the connectivity must fit the points).
pub fn write_cells_vtu<D: Dim>(
    path: impl AsRef<Path>,
    cells: &Cells,
    point_data: &[DataArray],
    cell_data: &[DataArray],
    encoding: VtuEncoding,
) -> Result<(), MeshError> {
    let path = path.as_ref();
    let io_err = |source| MeshError::Io {
        path: path.display().to_string(),
        source,
    };
    let n_points = cells.points.len() / D::D;
    let grid = Grid::of_cells::<D>(cells, n_points, point_data, cell_data, ("points", "cells"))
        .map_err(io_err)?;
    let file = File::create(path).map_err(io_err)?;
    let mut w = BufWriter::new(file);
    grid.write(&mut w, encoding).map_err(io_err)?;
    w.flush().map_err(io_err)
}

/// A `.pvd` time series: one `.vtu` file per step in a directory, listed with its time in
/// a `.pvd` collection file that ParaView opens as one time-dependent data set.
///
/// Step `i` (counted from 0) is written to `<dir>/<base_name>_<i:06>.vtu`; the collection
/// `<dir>/<base_name>.pvd` refers to the steps by relative file name and is rewritten
/// (atomically, through a temporary file and a rename) after every step, so the series of
/// an interrupted run stays readable.
#[derive(Clone, Debug)]
pub struct PvdSeries {
    dir: PathBuf,
    base_name: String,
    encoding: VtuEncoding,
    steps: Vec<(f64, String)>,
}

impl PvdSeries {
    /// Starts a series in `dir` (created with its parents if missing) with file names
    /// starting with `base_name`. An existing `.pvd` of the same name is overwritten at the
    /// first step. Data are written as raw appended binary; see
    /// [`PvdSeries::with_encoding`].
    ///
    /// # Errors
    ///
    /// [`MeshError::Io`] if the directory cannot be created, or (kind `InvalidInput`) if
    /// `base_name` is empty or contains a path separator.
    pub fn new(dir: impl AsRef<Path>, base_name: &str) -> Result<Self, MeshError> {
        let dir = dir.as_ref().to_path_buf();
        if base_name.is_empty() || base_name.contains(['/', '\\']) {
            return Err(MeshError::Io {
                path: dir.display().to_string(),
                source: invalid(format!(
                    "invalid series base name '{base_name}': it must be a non-empty file name without path separators"
                )),
            });
        }
        std::fs::create_dir_all(&dir).map_err(|source| MeshError::Io {
            path: dir.display().to_string(),
            source,
        })?;
        Ok(PvdSeries {
            dir,
            base_name: base_name.to_string(),
            encoding: VtuEncoding::RawBinary,
            steps: Vec::new(),
        })
    }

    /// Sets the encoding of the `.vtu` files written from now on.
    pub fn with_encoding(mut self, encoding: VtuEncoding) -> Self {
        self.encoding = encoding;
        self
    }

    /// The directory of the series.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Path of the `.pvd` collection file, `<dir>/<base_name>.pvd`.
    pub fn pvd_path(&self) -> PathBuf {
        self.dir.join(format!("{}.pvd", self.base_name))
    }

    /// The steps written so far: time (s) and `.vtu` file name relative to [`Self::dir`].
    pub fn steps(&self) -> &[(f64, String)] {
        &self.steps
    }

    /// Writes the next step at `time` (s) with [`write_vtu`]'s arguments and rewrites the
    /// `.pvd` file. Returns the path of the `.vtu` file written.
    ///
    /// # Errors
    ///
    /// As [`write_vtu`]; also [`MeshError::Io`] (kind `InvalidInput`) for a non-finite
    /// `time`. A failed step is not added to the series.
    pub fn write_step<D: Dim>(
        &mut self,
        time: f64,
        mesh: &Mesh<D>,
        points: Option<&[f64]>,
        point_data: &[DataArray],
        cell_data: &[DataArray],
    ) -> Result<PathBuf, MeshError> {
        let encoding = self.encoding;
        self.add_step(time, |path| {
            write_vtu_with(path, mesh, points, point_data, cell_data, encoding)
        })
    }

    /// Writes the next step of [`Cells`] ([`write_cells_vtu`]) and updates the `.pvd`
    /// file, like [`PvdSeries::write_step`].
    pub fn write_cells_step<D: Dim>(
        &mut self,
        time: f64,
        cells: &Cells,
        point_data: &[DataArray],
        cell_data: &[DataArray],
    ) -> Result<PathBuf, MeshError> {
        let encoding = self.encoding;
        self.add_step(time, |path| {
            write_cells_vtu::<D>(path, cells, point_data, cell_data, encoding)
        })
    }

    /// Writes the next step's file with `write` (refusing a non-finite time), then lists
    /// it in the `.pvd` file.
    fn add_step(
        &mut self,
        time: f64,
        write: impl FnOnce(&Path) -> Result<(), MeshError>,
    ) -> Result<PathBuf, MeshError> {
        let file_name = format!("{}_{:06}.vtu", self.base_name, self.steps.len());
        let path = self.dir.join(&file_name);
        if !time.is_finite() {
            return Err(MeshError::Io {
                path: path.display().to_string(),
                source: invalid(format!("time {time} is not finite")),
            });
        }
        write(&path)?;
        self.steps.push((time, file_name));
        self.write_pvd()?;
        Ok(path)
    }

    fn write_pvd(&self) -> Result<(), MeshError> {
        let mut s = String::new();
        s.push_str("<?xml version=\"1.0\"?>\n");
        s.push_str("<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n");
        s.push_str("  <Collection>\n");
        for (time, file) in &self.steps {
            s.push_str(&format!(
                "    <DataSet timestep=\"{time:?}\" group=\"\" part=\"0\" file=\"{}\"/>\n",
                escape_xml(file)
            ));
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        let path = self.pvd_path();
        let tmp = self.dir.join(format!("{}.pvd.tmp", self.base_name));
        std::fs::write(&tmp, s).map_err(|source| MeshError::Io {
            path: tmp.display().to_string(),
            source,
        })?;
        std::fs::rename(&tmp, &path).map_err(|source| MeshError::Io {
            path: path.display().to_string(),
            source,
        })
    }
}

fn invalid(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

fn escape_xml(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            _ => out.push(c),
        }
    }
    out
}

// ---------------------------------------------------------------------------------------
// Output arrays
// ---------------------------------------------------------------------------------------

/// How input tuples of `f64` become output tuples.
#[derive(Clone, Copy)]
enum Expand {
    /// Copy `n` values.
    Copy,
    /// Pad a `d`-vector to 3 components.
    Pad3(usize),
    /// Symmetric tensor of dimension `d` to a full 3x3 tensor.
    Sym(usize),
}

enum Source<'a> {
    F64(&'a [f64], Expand),
    I32(&'a [i32]),
    Connectivity(&'a [u32]),
    Offsets(usize),
    Types(u8),
    /// Per-cell values computed for the output (Quad4/Hex8 cells).
    F64Owned(Vec<f64>, Expand),
    I32Owned(Vec<i32>),
    OffsetList(Vec<i64>),
    TypeList(Vec<u8>),
}

/// One `DataArray` element of the output file.
struct OutArray<'a> {
    name: &'a str,
    /// Output components per tuple.
    ncomp: usize,
    /// Whether to write the `NumberOfComponents` attribute.
    write_ncomp: bool,
    n_tuples: usize,
    source: Source<'a>,
}

impl OutArray<'_> {
    fn vtk_type(&self) -> &'static str {
        match self.source {
            Source::F64(..) | Source::F64Owned(..) => "Float64",
            Source::I32(_) | Source::I32Owned(_) => "Int32",
            Source::Connectivity(_) | Source::Offsets(_) | Source::OffsetList(_) => "Int64",
            Source::Types(_) | Source::TypeList(_) => "UInt8",
        }
    }

    fn value_size(&self) -> u64 {
        match self.source {
            Source::F64(..)
            | Source::F64Owned(..)
            | Source::Connectivity(_)
            | Source::Offsets(_)
            | Source::OffsetList(_) => 8,
            Source::I32(_) | Source::I32Owned(_) => 4,
            Source::Types(_) | Source::TypeList(_) => 1,
        }
    }

    /// Length of the data in bytes (without the `UInt64` header).
    fn byte_len(&self) -> u64 {
        (self.n_tuples * self.ncomp) as u64 * self.value_size()
    }

    /// Writes the values: as little-endian bytes, or as text with one tuple per line.
    fn write_values(&self, w: &mut impl Write, ascii: bool) -> io::Result<()> {
        const INDENT: &str = "          ";
        let nc = self.ncomp;
        let mut t = [0.0f64; 9];
        for i in 0..self.n_tuples {
            if ascii {
                w.write_all(INDENT.as_bytes())?;
            }
            let owned_f64;
            let owned_i32;
            let source = match &self.source {
                Source::F64Owned(v, e) => {
                    owned_f64 = Source::F64(v, *e);
                    &owned_f64
                }
                Source::I32Owned(v) => {
                    owned_i32 = Source::I32(v);
                    &owned_i32
                }
                Source::OffsetList(v) => {
                    write_scalar(w, ascii, &v[i].to_le_bytes(), &v[i].to_string())?;
                    if ascii {
                        w.write_all(b"\n")?;
                    }
                    continue;
                }
                Source::TypeList(v) => {
                    write_scalar(w, ascii, &[v[i]], &v[i].to_string())?;
                    if ascii {
                        w.write_all(b"\n")?;
                    }
                    continue;
                }
                other => other,
            };
            match *source {
                Source::F64(v, expand) => {
                    match expand {
                        Expand::Copy => t[..nc].copy_from_slice(&v[i * nc..(i + 1) * nc]),
                        Expand::Pad3(d) => {
                            t[..3].fill(0.0);
                            t[..d].copy_from_slice(&v[i * d..(i + 1) * d]);
                        }
                        Expand::Sym(2) => {
                            let s = &v[i * 3..i * 3 + 3];
                            t = [s[0], s[2], 0.0, s[2], s[1], 0.0, 0.0, 0.0, 0.0];
                        }
                        Expand::Sym(_) => {
                            let s = &v[i * 6..i * 6 + 6];
                            t = [s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2]];
                        }
                    }
                    for (k, x) in t[..nc].iter().enumerate() {
                        if ascii {
                            let sep = if k == 0 { "" } else { " " };
                            write!(w, "{sep}{x:?}")?;
                        } else {
                            w.write_all(&x.to_le_bytes())?;
                        }
                    }
                }
                Source::I32(v) => {
                    if ascii {
                        write!(w, "{}", v[i])?;
                    } else {
                        w.write_all(&v[i].to_le_bytes())?;
                    }
                }
                Source::Connectivity(c) => {
                    for (k, &n) in c[i * nc..(i + 1) * nc].iter().enumerate() {
                        if ascii {
                            let sep = if k == 0 { "" } else { " " };
                            write!(w, "{sep}{n}")?;
                        } else {
                            w.write_all(&i64::from(n).to_le_bytes())?;
                        }
                    }
                }
                Source::Offsets(npe) => {
                    let off = ((i + 1) * npe) as i64;
                    if ascii {
                        write!(w, "{off}")?;
                    } else {
                        w.write_all(&off.to_le_bytes())?;
                    }
                }
                Source::Types(t) => {
                    if ascii {
                        write!(w, "{t}")?;
                    } else {
                        w.write_all(&[t])?;
                    }
                }
                Source::F64Owned(..)
                | Source::I32Owned(_)
                | Source::OffsetList(_)
                | Source::TypeList(_) => unreachable!("resolved above"),
            }
            if ascii {
                w.write_all(b"\n")?;
            }
        }
        Ok(())
    }
}

/// Writes one scalar as bytes or as text.
fn write_scalar(w: &mut impl Write, ascii: bool, bytes: &[u8], text: &str) -> io::Result<()> {
    if ascii {
        w.write_all(text.as_bytes())
    } else {
        w.write_all(bytes)
    }
}

/// A validated grid ready to be written.
struct Grid<'a> {
    n_points: usize,
    n_cells: usize,
    point_data: Vec<OutArray<'a>>,
    cell_data: Vec<OutArray<'a>>,
    /// Points, connectivity, offsets, types.
    geometry: Vec<OutArray<'a>>,
}

impl<'a> Grid<'a> {
    fn new<D: Dim>(
        mesh: &'a Mesh<D>,
        points: Option<&'a [f64]>,
        point_data: &[DataArray<'a>],
        cell_data: &[DataArray<'a>],
    ) -> io::Result<Self> {
        if mesh.cells().has_composite() {
            return Self::of_mesh_cells(mesh, points, point_data, cell_data);
        }
        let cells = Cells {
            points: points.unwrap_or(mesh.coords()),
            connectivity: mesh.elements(),
            nodes_per_cell: D::NODES_PER_ELEM,
            cell_type: D::ELEMENT.vtk_cell_type(),
        };
        Self::of_cells::<D>(
            &cells,
            mesh.n_nodes(),
            point_data,
            cell_data,
            ("nodes", "elements"),
        )
    }

    /// A mesh with Quad4/Hex8 cells: written as its cells (VTK_QUAD, VTK_HEXAHEDRON,
    /// VTK_TRIANGLE, VTK_TETRA), each cell's data the volume-weighted mean of its
    /// simplices' values (integers: its first simplex's value).
    fn of_mesh_cells<D: Dim>(
        mesh: &'a Mesh<D>,
        points: Option<&'a [f64]>,
        point_data: &[DataArray<'a>],
        cell_data: &[DataArray<'a>],
    ) -> io::Result<Self> {
        let ne = mesh.n_elements();
        // The element-level checks, then the per-cell means.
        let per_element = out_arrays::<D>("cell", "elements", cell_data, ne)?;
        let simplex = Cells {
            points: points.unwrap_or(mesh.coords()),
            connectivity: mesh.elements(),
            nodes_per_cell: D::NODES_PER_ELEM,
            cell_type: D::ELEMENT.vtk_cell_type(),
        };
        let mut grid = Self::of_cells::<D>(
            &simplex,
            mesh.n_nodes(),
            point_data,
            &[],
            ("nodes", "elements"),
        )?;
        let cells = mesh.cells();
        let nc = cells.len();
        let weights: Vec<f64> = (0..ne).map(|e| mesh.element_measure(e)).collect();
        let mut offsets = Vec::with_capacity(nc);
        let mut end = 0i64;
        for c in 0..nc {
            end += cells.nodes(c).len() as i64;
            offsets.push(end);
        }
        grid.n_cells = nc;
        grid.geometry[1] = OutArray {
            name: "connectivity",
            ncomp: 1,
            write_ncomp: false,
            n_tuples: cells.all_nodes().len(),
            source: Source::Connectivity(cells.all_nodes()),
        };
        grid.geometry[2] = OutArray {
            name: "offsets",
            ncomp: 1,
            write_ncomp: false,
            n_tuples: nc,
            source: Source::OffsetList(offsets),
        };
        grid.geometry[3] = OutArray {
            name: "types",
            ncomp: 1,
            write_ncomp: false,
            n_tuples: nc,
            source: Source::TypeList(cells.kinds().iter().map(|k| k.vtk_cell_type()).collect()),
        };
        grid.cell_data = per_element
            .into_iter()
            .zip(cell_data)
            .map(|(out, input)| {
                let source = match *input {
                    DataArray::Int { values, .. } => {
                        Source::I32Owned((0..nc).map(|c| values[cells.elements(c).start]).collect())
                    }
                    _ => {
                        let (values, expand) = match out.source {
                            Source::F64(v, e) => (v, e),
                            _ => unreachable!("a float array"),
                        };
                        let stride = input.input_stride::<D>();
                        let mut mean = vec![0.0; nc * stride];
                        for c in 0..nc {
                            let els = cells.elements(c);
                            let total: f64 = els.clone().map(|e| weights[e]).sum();
                            for e in els {
                                for k in 0..stride {
                                    mean[c * stride + k] +=
                                        weights[e] / total * values[e * stride + k];
                                }
                            }
                        }
                        Source::F64Owned(mean, expand)
                    }
                };
                OutArray {
                    n_tuples: nc,
                    source,
                    ..out
                }
            })
            .collect();
        Ok(grid)
    }

    /// `n_points`: the points expected in `cells.points` (stride D).
    fn of_cells<D: Dim>(
        cells: &Cells<'a>,
        n_points: usize,
        point_data: &[DataArray<'a>],
        cell_data: &[DataArray<'a>],
        (point_kind, cell_kind): (&str, &str),
    ) -> io::Result<Self> {
        let (d, npe) = (D::D, cells.nodes_per_cell);
        let coords = cells.points;
        if coords.len() != n_points * d {
            return Err(invalid(format!(
                "points array has {} values, expected {} ({n_points} {point_kind} x {d} coordinates)",
                coords.len(),
                n_points * d
            )));
        }
        if npe == 0 || cells.connectivity.len() % npe != 0 {
            return Err(invalid(format!(
                "connectivity has {} entries, not a multiple of {npe} nodes per cell",
                cells.connectivity.len()
            )));
        }
        let n_cells = cells.connectivity.len() / npe;
        if let Some(bad) = cells.connectivity.iter().find(|&&n| n as usize >= n_points) {
            return Err(invalid(format!(
                "connectivity refers to point {bad}, but there are {n_points} points"
            )));
        }
        let geometry = vec![
            OutArray {
                name: "Points",
                ncomp: 3,
                write_ncomp: true,
                n_tuples: n_points,
                source: Source::F64(coords, Expand::Pad3(d)),
            },
            OutArray {
                name: "connectivity",
                ncomp: npe,
                write_ncomp: false,
                n_tuples: n_cells,
                source: Source::Connectivity(cells.connectivity),
            },
            OutArray {
                name: "offsets",
                ncomp: 1,
                write_ncomp: false,
                n_tuples: n_cells,
                source: Source::Offsets(npe),
            },
            OutArray {
                name: "types",
                ncomp: 1,
                write_ncomp: false,
                n_tuples: n_cells,
                source: Source::Types(cells.cell_type),
            },
        ];
        Ok(Grid {
            n_points,
            n_cells,
            point_data: out_arrays::<D>("point", point_kind, point_data, n_points)?,
            cell_data: out_arrays::<D>("cell", cell_kind, cell_data, n_cells)?,
            geometry,
        })
    }

    fn write(&self, w: &mut impl Write, encoding: VtuEncoding) -> io::Result<()> {
        let raw = encoding == VtuEncoding::RawBinary;
        writeln!(w, "<?xml version=\"1.0\"?>")?;
        writeln!(
            w,
            "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
        )?;
        writeln!(w, "  <UnstructuredGrid>")?;
        writeln!(
            w,
            "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
            self.n_points, self.n_cells
        )?;
        let mut offset = 0u64;
        let sections: [(&str, &[OutArray]); 4] = [
            ("PointData", &self.point_data),
            ("CellData", &self.cell_data),
            ("Points", &self.geometry[..1]),
            ("Cells", &self.geometry[1..]),
        ];
        for (tag, arrays) in sections {
            writeln!(w, "      <{tag}>")?;
            for a in arrays {
                write!(
                    w,
                    "        <DataArray type=\"{}\" Name=\"{}\"",
                    a.vtk_type(),
                    escape_xml(a.name)
                )?;
                if a.write_ncomp {
                    write!(w, " NumberOfComponents=\"{}\"", a.ncomp)?;
                }
                if raw {
                    writeln!(w, " format=\"appended\" offset=\"{offset}\"/>")?;
                    offset += 8 + a.byte_len();
                } else {
                    writeln!(w, " format=\"ascii\">")?;
                    a.write_values(w, true)?;
                    writeln!(w, "        </DataArray>")?;
                }
            }
            writeln!(w, "      </{tag}>")?;
        }
        writeln!(w, "    </Piece>")?;
        writeln!(w, "  </UnstructuredGrid>")?;
        if raw {
            writeln!(w, "  <AppendedData encoding=\"raw\">")?;
            write!(w, "   _")?;
            for (_, arrays) in sections {
                for a in arrays {
                    w.write_all(&a.byte_len().to_le_bytes())?;
                    a.write_values(w, false)?;
                }
            }
            writeln!(w)?;
            writeln!(w, "  </AppendedData>")?;
        }
        writeln!(w, "</VTKFile>")
    }
}

/// Checks the user arrays against the entity count and turns them into output arrays.
fn out_arrays<'a, D: Dim>(
    kind: &str,
    entities: &str,
    arrays: &[DataArray<'a>],
    count: usize,
) -> io::Result<Vec<OutArray<'a>>> {
    let mut names = HashSet::new();
    let mut out = Vec::with_capacity(arrays.len());
    for a in arrays {
        let name = a.name();
        if name.is_empty() {
            return Err(invalid(format!("{kind} data array with an empty name")));
        }
        if !names.insert(name) {
            return Err(invalid(format!(
                "{kind} data array name '{name}' is used twice"
            )));
        }
        let stride = a.input_stride::<D>();
        if a.len() != count * stride {
            return Err(invalid(format!(
                "{kind} data array '{name}' has {} values, expected {} ({count} {entities} x {stride} components)",
                a.len(),
                count * stride
            )));
        }
        let (ncomp, source) = match *a {
            DataArray::Scalar { values, .. } => (1, Source::F64(values, Expand::Copy)),
            DataArray::Vector { values, .. } => (3, Source::F64(values, Expand::Pad3(D::D))),
            DataArray::SymTensor { values, .. } => (9, Source::F64(values, Expand::Sym(D::D))),
            DataArray::Int { values, .. } => (1, Source::I32(values)),
        };
        out.push(OutArray {
            name,
            ncomp,
            write_ncomp: true,
            n_tuples: count,
            source,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Dim2, Dim3};
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A fresh, empty temporary directory for one test.
    fn tmp_dir(tag: &str) -> PathBuf {
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("pcdc-vtu-{}-{tag}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn square() -> Mesh<Dim2> {
        Mesh::new(
            vec![0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0],
            vec![0, 1, 2, 0, 2, 3],
        )
        .unwrap()
    }

    fn tets() -> Mesh<Dim3> {
        let coords = vec![
            0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0,
        ];
        Mesh::new_reoriented(coords, vec![0, 1, 2, 3, 1, 2, 3, 4]).unwrap()
    }

    /// The text values of the ASCII `DataArray` named `name`.
    fn ascii_array(xml: &str, name: &str) -> Vec<f64> {
        let key = format!("Name=\"{name}\"");
        let i = xml.find(&key).unwrap_or_else(|| panic!("no array {name}"));
        let start = i + xml[i..].find('>').unwrap() + 1;
        let end = start + xml[start..].find("</DataArray>").unwrap();
        xml[start..end]
            .split_whitespace()
            .map(|t| t.parse().unwrap())
            .collect()
    }

    /// The value of attribute `attr` in the `DataArray` element named `name`.
    fn attribute(xml: &str, name: &str, attr: &str) -> String {
        let i = xml.find(&format!("Name=\"{name}\"")).unwrap();
        let elem_start = xml[..i].rfind('<').unwrap();
        let elem_end = i + xml[i..].find('>').unwrap();
        let elem = &xml[elem_start..elem_end];
        let key = format!(" {attr}=\"");
        let a = elem
            .find(&key)
            .unwrap_or_else(|| panic!("no {attr} in {elem}"))
            + key.len();
        elem[a..a + elem[a..].find('"').unwrap()].to_string()
    }

    /// A mesh with Quad4 and Tri3 cells is written as those cells, each with the
    /// volume-weighted mean of its simplices' data; the binary file has the same layout.
    #[test]
    fn quad_and_triangle_cells_are_written_as_cells() {
        let mesh = crate::builders::ring_mixed([0.0, 0.0], 1.0, 2.0, 0.8).unwrap();
        let ne = mesh.n_elements();
        let nc = mesh.n_cells();
        assert!(nc < ne);
        let scalar: Vec<f64> = (0..ne).map(|e| e as f64).collect();
        let ids: Vec<i32> = (0..ne as i32).collect();
        let dir = tmp_dir("quad_cells");
        let path = dir.join("mixed.vtu");
        let data = [
            DataArray::Scalar {
                name: "s",
                values: &scalar,
            },
            DataArray::Int {
                name: "id",
                values: &ids,
            },
        ];
        write_vtu_ascii(&path, &mesh, None, &[], &data).unwrap();
        let xml = std::fs::read_to_string(&path).unwrap();
        assert!(xml.contains(&format!("NumberOfCells=\"{nc}\"")));
        let types = ascii_array(&xml, "types");
        assert!(types.contains(&9.0) && types.contains(&5.0));
        let offsets = ascii_array(&xml, "offsets");
        assert_eq!(
            *offsets.last().unwrap() as usize,
            mesh.cells().all_nodes().len()
        );
        let (s, id) = (ascii_array(&xml, "s"), ascii_array(&xml, "id"));
        for c in 0..nc {
            let els = mesh.cell_elements(c);
            let total: f64 = els.clone().map(|e| mesh.element_measure(e)).sum();
            let want: f64 = els
                .clone()
                .map(|e| mesh.element_measure(e) * e as f64)
                .sum::<f64>()
                / total;
            assert!(
                (s[c] - want).abs() < 1e-12 * want.abs().max(1.0),
                "cell {c}: {} vs {want}",
                s[c]
            );
            assert_eq!(id[c] as usize, els.start);
        }
        write_vtu(dir.join("mixed_bin.vtu"), &mesh, None, &[], &data).unwrap();
        let bin = std::fs::read(dir.join("mixed_bin.vtu")).unwrap();
        assert!(find(&bin, b"NumberOfCells") > 0);
    }

    #[test]
    fn line_cells_with_their_data() {
        let dir = tmp_dir("cells");
        let path = dir.join("net.vtu");
        let points = [0.0, 0.0, 1.0, 0.0, 1.0, 1.0];
        let cells = Cells {
            points: &points,
            connectivity: &[0, 1, 1, 2],
            nodes_per_cell: 2,
            cell_type: VTK_LINE,
        };
        let p = [1.0, 2.0, 3.0];
        let a = [1e-4, 2e-4];
        write_cells_vtu::<Dim2>(
            &path,
            &cells,
            &[DataArray::Scalar {
                name: "pressure",
                values: &p,
            }],
            &[DataArray::Scalar {
                name: "aperture",
                values: &a,
            }],
            VtuEncoding::Ascii,
        )
        .unwrap();
        let xml = std::fs::read_to_string(&path).unwrap();
        assert!(xml.contains("NumberOfPoints=\"3\" NumberOfCells=\"2\""));
        assert_eq!(ascii_array(&xml, "types"), vec![3.0, 3.0]);
        assert_eq!(ascii_array(&xml, "connectivity"), vec![0.0, 1.0, 1.0, 2.0]);
        assert_eq!(ascii_array(&xml, "aperture"), a.to_vec());
        // A cell beyond the points, or data of the wrong length, is refused by name.
        let bad = Cells {
            connectivity: &[0, 3],
            ..cells
        };
        let e = write_cells_vtu::<Dim2>(&path, &bad, &[], &[], VtuEncoding::Ascii).unwrap_err();
        assert!(e.to_string().contains("point 3"), "{e}");
        let e = write_cells_vtu::<Dim2>(
            &path,
            &cells,
            &[],
            &[DataArray::Scalar {
                name: "aperture",
                values: &p,
            }],
            VtuEncoding::Ascii,
        )
        .unwrap_err();
        assert!(e.to_string().contains("aperture"), "{e}");
    }

    fn find(hay: &[u8], needle: &[u8]) -> usize {
        hay.windows(needle.len()).position(|w| w == needle).unwrap()
    }

    #[test]
    fn ascii_2d_round_trip() {
        let m = square();
        let dir = tmp_dir("ascii2d");
        let path = dir.join("sq.vtu");
        let deformed = [0.0, 0.0, 1.1, 0.0, 1.1, 1.2, 0.0, 1.0];
        let u = [0.0, 0.0, 0.1, 0.0, 0.1, 0.2, 0.0, 0.0];
        let p = [1.0, 2.0, 3.0, 4.0];
        let ids = [7, -3];
        let s = [1.0, 2.0, 0.5, -1.0, -2.0, 0.25];
        write_vtu_ascii(
            &path,
            &m,
            Some(&deformed),
            &[
                DataArray::Vector {
                    name: "u",
                    values: &u,
                },
                DataArray::Scalar {
                    name: "p",
                    values: &p,
                },
            ],
            &[
                DataArray::Int {
                    name: "id",
                    values: &ids,
                },
                DataArray::SymTensor {
                    name: "stress",
                    values: &s,
                },
            ],
        )
        .unwrap();
        let xml = std::fs::read_to_string(&path).unwrap();
        assert!(xml.contains("<Piece NumberOfPoints=\"4\" NumberOfCells=\"2\">"));
        assert!(!xml.contains("AppendedData"));
        assert_eq!(
            ascii_array(&xml, "Points"),
            vec![0.0, 0.0, 0.0, 1.1, 0.0, 0.0, 1.1, 1.2, 0.0, 0.0, 1.0, 0.0]
        );
        assert_eq!(
            ascii_array(&xml, "connectivity"),
            vec![0.0, 1.0, 2.0, 0.0, 2.0, 3.0]
        );
        assert_eq!(ascii_array(&xml, "offsets"), vec![3.0, 6.0]);
        assert_eq!(ascii_array(&xml, "types"), vec![5.0, 5.0]);
        assert_eq!(
            ascii_array(&xml, "u"),
            vec![0.0, 0.0, 0.0, 0.1, 0.0, 0.0, 0.1, 0.2, 0.0, 0.0, 0.0, 0.0]
        );
        assert_eq!(ascii_array(&xml, "p"), p.to_vec());
        assert_eq!(ascii_array(&xml, "id"), vec![7.0, -3.0]);
        assert_eq!(
            ascii_array(&xml, "stress"),
            vec![
                1.0, 0.5, 0.0, 0.5, 2.0, 0.0, 0.0, 0.0, 0.0, //
                -1.0, 0.25, 0.0, 0.25, -2.0, 0.0, 0.0, 0.0, 0.0
            ]
        );
        assert_eq!(attribute(&xml, "u", "NumberOfComponents"), "3");
        assert_eq!(attribute(&xml, "stress", "NumberOfComponents"), "9");
        assert_eq!(attribute(&xml, "id", "type"), "Int32");
        assert_eq!(attribute(&xml, "connectivity", "type"), "Int64");
        assert_eq!(attribute(&xml, "types", "type"), "UInt8");
        // Point data before cell data, in their own sections.
        let (pd, cd) = (
            xml.find("<PointData>").unwrap(),
            xml.find("<CellData>").unwrap(),
        );
        assert!(pd < xml.find("Name=\"u\"").unwrap() && xml.find("Name=\"u\"").unwrap() < cd);
        assert!(cd < xml.find("Name=\"id\"").unwrap());
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn ascii_3d_round_trip_with_mesh_coordinates() {
        let m = tets();
        let dir = tmp_dir("ascii3d");
        let path = dir.join("t.vtu");
        let s: Vec<f64> = (0..12).map(|i| i as f64).collect();
        let v: Vec<f64> = (0..15).map(|i| 0.5 * i as f64).collect();
        write_vtu_with(
            &path,
            &m,
            None,
            &[DataArray::Vector {
                name: "v",
                values: &v,
            }],
            &[DataArray::SymTensor {
                name: "s",
                values: &s,
            }],
            VtuEncoding::Ascii,
        )
        .unwrap();
        let xml = std::fs::read_to_string(&path).unwrap();
        assert_eq!(ascii_array(&xml, "Points"), m.coords().to_vec());
        let conn: Vec<f64> = m.elements().iter().map(|&n| n as f64).collect();
        assert_eq!(ascii_array(&xml, "connectivity"), conn);
        assert_eq!(ascii_array(&xml, "offsets"), vec![4.0, 8.0]);
        assert_eq!(ascii_array(&xml, "types"), vec![10.0, 10.0]);
        assert_eq!(ascii_array(&xml, "v"), v);
        // xx yy zz xy yz xz = 0 1 2 3 4 5 -> full row-major tensor.
        assert_eq!(
            ascii_array(&xml, "s")[..9],
            [0.0, 3.0, 5.0, 3.0, 1.0, 4.0, 5.0, 4.0, 2.0]
        );
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn length_mismatch_is_an_error_naming_the_array() {
        let m = square();
        let dir = tmp_dir("mismatch");
        let path = dir.join("bad.vtu");
        let short = [0.0; 3];
        let check = |err: MeshError, needle: &str| {
            let MeshError::Io { source, path: p } = &err else {
                panic!("{err}")
            };
            assert_eq!(source.kind(), io::ErrorKind::InvalidInput);
            assert!(p.ends_with("bad.vtu"));
            assert!(err.to_string().contains(needle), "{err}");
        };
        let e = write_vtu(
            &path,
            &m,
            None,
            &[DataArray::Vector {
                name: "disp",
                values: &short,
            }],
            &[],
        )
        .unwrap_err();
        check(e, "point data array 'disp' has 3 values, expected 8");
        let e = write_vtu(
            &path,
            &m,
            None,
            &[],
            &[DataArray::Scalar {
                name: "dmg",
                values: &short,
            }],
        )
        .unwrap_err();
        check(e, "cell data array 'dmg' has 3 values, expected 2");
        let e = write_vtu(
            &path,
            &m,
            None,
            &[],
            &[DataArray::SymTensor {
                name: "sig",
                values: &[0.0; 4],
            }],
        )
        .unwrap_err();
        check(e, "'sig' has 4 values, expected 6");
        let e = write_vtu(
            &path,
            &m,
            None,
            &[],
            &[DataArray::Int {
                name: "g",
                values: &[1],
            }],
        )
        .unwrap_err();
        check(e, "'g'");
        let e = write_vtu(&path, &m, Some(&short), &[], &[]).unwrap_err();
        check(e, "points array has 3 values, expected 8");
        let p = [0.0; 4];
        let e = write_vtu(
            &path,
            &m,
            None,
            &[
                DataArray::Scalar {
                    name: "a",
                    values: &p,
                },
                DataArray::Scalar {
                    name: "a",
                    values: &p,
                },
            ],
            &[],
        )
        .unwrap_err();
        check(e, "'a' is used twice");
        assert!(!path.exists(), "nothing is written for invalid arrays");
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn raw_binary_appended_section_has_the_right_byte_counts() {
        let m = square();
        let dir = tmp_dir("raw");
        let path = dir.join("raw.vtu");
        let u = [0.0, 0.0, 0.1, 0.0, 0.1, 0.2, 0.0, 0.0];
        let s = [1.0, 2.0, 0.5, -1.0, -2.0, 0.25];
        let ids = [4, 5];
        write_vtu(
            &path,
            &m,
            None,
            &[DataArray::Vector {
                name: "u",
                values: &u,
            }],
            &[
                DataArray::SymTensor {
                    name: "stress",
                    values: &s,
                },
                DataArray::Int {
                    name: "id",
                    values: &ids,
                },
            ],
        )
        .unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let marker = b"<AppendedData encoding=\"raw\">";
        let head_end = find(&bytes, marker);
        let xml = std::str::from_utf8(&bytes[..head_end]).unwrap();
        let base = head_end + find(&bytes[head_end..], b"_") + 1;
        let u64_at = |i: usize| u64::from_le_bytes(bytes[i..i + 8].try_into().unwrap());
        let f64_at = |i: usize| f64::from_le_bytes(bytes[i..i + 8].try_into().unwrap());
        // (name, number of values, bytes per value), in file order.
        let arrays = [
            ("u", 4 * 3, 8),
            ("stress", 2 * 9, 8),
            ("id", 2, 4),
            ("Points", 4 * 3, 8),
            ("connectivity", 6, 8),
            ("offsets", 2, 8),
            ("types", 2, 1),
        ];
        let mut expected_offset = 0usize;
        for (name, n, size) in arrays {
            assert_eq!(attribute(xml, name, "format"), "appended");
            let off: usize = attribute(xml, name, "offset").parse().unwrap();
            assert_eq!(off, expected_offset, "offset of {name}");
            assert_eq!(
                u64_at(base + off),
                (n * size) as u64,
                "byte count of {name}"
            );
            expected_offset += 8 + n * size;
        }
        // Float64 arrays hold 8 * n bytes, and decode to the expected values.
        let off: usize = attribute(xml, "u", "offset").parse().unwrap();
        assert_eq!(u64_at(base + off), 8 * 12);
        let got: Vec<f64> = (0..12).map(|k| f64_at(base + off + 8 + 8 * k)).collect();
        assert_eq!(
            got,
            vec![0.0, 0.0, 0.0, 0.1, 0.0, 0.0, 0.1, 0.2, 0.0, 0.0, 0.0, 0.0]
        );
        let off: usize = attribute(xml, "Points", "offset").parse().unwrap();
        let got: Vec<f64> = (0..12).map(|k| f64_at(base + off + 8 + 8 * k)).collect();
        assert_eq!(
            got,
            vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0]
        );
        let off: usize = attribute(xml, "connectivity", "offset").parse().unwrap();
        let conn: Vec<u64> = (0..6).map(|k| u64_at(base + off + 8 + 8 * k)).collect();
        assert_eq!(conn, vec![0, 1, 2, 0, 2, 3]);
        let off: usize = attribute(xml, "types", "offset").parse().unwrap();
        assert_eq!(&bytes[base + off + 8..base + off + 10], &[5, 5]);
        // The appended block ends exactly after the last array.
        assert_eq!(
            &bytes[base + expected_offset..],
            b"\n  </AppendedData>\n</VTKFile>\n"
        );
        assert!(xml.contains("header_type=\"UInt64\""));
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn pvd_lists_every_step_with_its_time() {
        let m = square();
        let dir = tmp_dir("pvd").join("nested");
        let mut series = PvdSeries::new(&dir, "run").unwrap();
        assert!(dir.is_dir());
        let times = [0.0, 1.5e-6, 2.0e-3];
        for (k, &t) in times.iter().enumerate() {
            let d = [t; 2];
            let path = series
                .write_step(
                    t,
                    &m,
                    None,
                    &[],
                    &[DataArray::Scalar {
                        name: "d",
                        values: &d,
                    }],
                )
                .unwrap();
            assert_eq!(path, dir.join(format!("run_{k:06}.vtu")));
            assert!(path.is_file());
            // The collection is complete after every step.
            let pvd = std::fs::read_to_string(series.pvd_path()).unwrap();
            assert_eq!(pvd.matches("<DataSet ").count(), k + 1);
        }
        let pvd = std::fs::read_to_string(dir.join("run.pvd")).unwrap();
        assert!(pvd.contains("type=\"Collection\""));
        let entries: Vec<(f64, String)> = pvd
            .lines()
            .filter(|l| l.contains("<DataSet "))
            .map(|l| {
                let get = |a: &str| {
                    let k = l.find(&format!("{a}=\"")).unwrap() + a.len() + 2;
                    l[k..k + l[k..].find('"').unwrap()].to_string()
                };
                (get("timestep").parse().unwrap(), get("file"))
            })
            .collect();
        assert_eq!(
            entries,
            vec![
                (0.0, "run_000000.vtu".to_string()),
                (1.5e-6, "run_000001.vtu".to_string()),
                (2.0e-3, "run_000002.vtu".to_string()),
            ]
        );
        assert_eq!(series.steps(), &entries[..]);
        assert!(!dir.join("run.pvd.tmp").exists());
        // A failed step is not listed.
        assert!(series
            .write_step(
                3.0,
                &m,
                None,
                &[DataArray::Scalar {
                    name: "d",
                    values: &[0.0]
                }],
                &[]
            )
            .is_err());
        assert!(series.write_step(f64::NAN, &m, None, &[], &[]).is_err());
        assert_eq!(series.steps().len(), 3);
        assert!(PvdSeries::new(&dir, "a/b").is_err());
        assert!(PvdSeries::new(&dir, "").is_err());
        std::fs::remove_dir_all(dir.parent().unwrap()).unwrap();
    }

    #[test]
    fn names_are_xml_escaped() {
        let m = square();
        let dir = tmp_dir("escape");
        let path = dir.join("e.vtu");
        let p = [0.0; 4];
        write_vtu_ascii(
            &path,
            &m,
            None,
            &[DataArray::Scalar {
                name: "a<\"b\"&c>",
                values: &p,
            }],
            &[],
        )
        .unwrap();
        let xml = std::fs::read_to_string(&path).unwrap();
        assert!(
            xml.contains("Name=\"a&lt;&quot;b&quot;&amp;c&gt;\""),
            "{xml}"
        );
        std::fs::remove_dir_all(dir).unwrap();
    }
}
