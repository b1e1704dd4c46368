//! Gmsh MSH 4.1 ASCII import (manual chapter 4).
//!
//! [`read_msh`] and [`parse_msh`] turn a Gmsh mesh into a [`Mesh`]:
//!
//! * **Format.** Only MSH 4.1 ASCII is read. Export from Gmsh with `gmsh -format msh41`
//!   (or `Mesh.MshFileVersion = 4.1;`) and `Mesh.Binary = 0;`. Version 2.x, 4.0 and binary
//!   files are rejected with a [`MeshError::Parse`] that says so.
//! * **Sections.** `$MeshFormat`, `$PhysicalNames`, `$Entities`, `$Nodes` and `$Elements`
//!   are read; any other section (`$Periodic`, `$NodeData`, `$Comments`, ...) is skipped.
//! * **Elements.** The linear elements of the top dimension (Gmsh type 2, 3-node
//!   triangles, and type 3, 4-node quadrangles, for [`Dim2`](crate::Dim2); type 4, 4-node
//!   tetrahedra, and type 5, 8-node hexahedra, for [`Dim3`](crate::Dim3)), mixed freely,
//!   become the mesh cells, reoriented where needed; quadrangles and hexahedra are cut
//!   into simplices as [`crate::cells`] describes, and a twisted or degenerate one is an
//!   error naming its tag and line. Any other element type of the top dimension (prisms,
//!   pyramids, second-order elements, ...) is an error naming the type and line. Elements of a dimension above the mesh
//!   dimension are an error as well (a 3D file read as 2D).
//! * **Nodes.** Node tags may be sparse and in any order. Nodes used by no top-dimension
//!   element are dropped; the remaining nodes are numbered 0, 1, ... in increasing tag
//!   order. In 2D the z coordinate is dropped and must be zero (within `1e-9` times the
//!   in-plane mesh size). Coordinates are in the file's length unit, taken as metres, and
//!   must be finite with magnitude at most `1e100`.
//! * **Groups.** Every physical group becomes groups named after its physical name, or
//!   `physical_<tag>` when it has none:
//!   - a physical group of the top dimension gives an element group and a node group;
//!   - a physical group of dimension `D - 1` (lines in 2D, triangles or quadrangles in 3D)
//!     gives a face group (each line/triangle is matched with the mesh face with the same
//!     nodes, a quadrangle with the two triangles a hexahedron's face is cut into; an
//!     element that is no face of the mesh is an error naming its line) and a node group;
//!   - lower-dimensional physical groups (points, and curves in 3D) give node groups;
//!   - every physical curve group (2D or 3D) also gives its 2-node lines, as pairs of
//!     mesh nodes, in [`MshImport::lines`] (the path of a bolt along an embedded curve).
//!
//!   Node groups of the same name from different dimensions are merged. Lower-dimensional
//!   elements that belong to no physical group are ignored, whatever their type.
//!
//! * **Encoding.** The text is UTF-8; a leading byte-order mark (as some Windows editors
//!   write) is skipped.
//! * **Coincident nodes.** Nodes used by elements that lie at the same position (within
//!   [`COINCIDENT_REL_TOL`] times the largest bounding-box extent) are not merged by
//!   default: the elements on either side then share no face and the mesh is cut there,
//!   which is what unmerged Gmsh surfaces or volumes give. [`parse_msh_with`] and
//!   [`read_msh_with`] return an [`ImportWarning::CoincidentNodes`] for them, or merge them
//!   into the node of lowest tag with [`ImportOptions::merge_coincident`];
//!   [`read_msh`] and [`parse_msh`] print the warnings to standard error.
//!
//! Every malformed or truncated input gives a [`MeshError::Parse`] with the 1-based line
//! number (the last line of the file for an unexpected end of file) and a message; the
//! parser never panics on bad input.
//!
//! ```no_run
//! use pcdc_mesh::{gmsh, Dim2};
//! let mesh = gmsh::read_msh::<Dim2>("specimen.msh")?;
//! let left = &mesh.groups().faces["left"];
//! # let _ = left;
//! # Ok::<(), pcdc_mesh::MeshError>(())
//! ```

use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use std::str::FromStr;

use crate::{Dim, ElementKind, Mesh, MeshError};

mod coincident;
pub use coincident::{ImportOptions, ImportWarning, COINCIDENT_REL_TOL};

/// The result of [`parse_msh_with`] and [`read_msh_with`].
#[derive(Clone, Debug)]
pub struct MshImport<D: Dim> {
    /// The mesh.
    pub mesh: Mesh<D>,
    /// What the import accepted but is probably not what the file meant.
    pub warnings: Vec<ImportWarning>,
    /// Number of nodes merged into a coincident node of lower tag
    /// ([`ImportOptions::merge_coincident`]).
    pub merged_nodes: usize,
    /// The 2-node line elements of every physical curve group (in 2D and 3D), by group
    /// name, as pairs of mesh node indices in the file's order: the path of a bolt or
    /// cable drilled along an embedded curve (`pcdc_bolt::Bolt::from_line_group`). The
    /// mesh's own groups keep a 3D curve as a node group only.
    pub lines: BTreeMap<String, Vec<[u32; 2]>>,
}

use crate::MAX_COORD;

/// A 2D mesh node must have `|z| <= Z_REL_TOL * (largest in-plane bounding box extent)`.
const Z_REL_TOL: f64 = 1e-9;

const EXPORT_HINT: &str =
    "export the mesh as MSH 4.1 ASCII (`gmsh -format msh41` with `Mesh.Binary = 0`, or File > Export > Gmsh MSH, 'Version 4 ASCII')";

/// Reads a Gmsh MSH 4.1 ASCII file into a mesh of dimension `D`.
///
/// See the [module documentation](self) for what is read and how physical groups become
/// node, element and face groups. Coordinates are taken as metres.
///
/// # Errors
///
/// [`MeshError::Io`] if the file cannot be read; [`MeshError::Parse`] (with the file name
/// and line) if its content is not a valid MSH 4.1 ASCII mesh of dimension `D` or the
/// resulting mesh fails the checks of [`Mesh::new_reoriented`].
pub fn read_msh<D: Dim>(path: impl AsRef<Path>) -> Result<Mesh<D>, MeshError> {
    let import = read_msh_with::<D>(path.as_ref(), &ImportOptions::default())?;
    Ok(print_warnings(import, &path.as_ref().display().to_string()))
}

/// Prints the warnings of an import to standard error and returns its mesh.
fn print_warnings<D: Dim>(import: MshImport<D>, file: &str) -> Mesh<D> {
    for w in &import.warnings {
        eprintln!("warning: {file}: {w}");
    }
    import.mesh
}

/// [`read_msh`] with options, returning the warnings instead of printing them.
///
/// # Errors
///
/// As [`read_msh`], and [`MeshError::InvalidParameter`] for invalid options.
pub fn read_msh_with<D: Dim>(
    path: impl AsRef<Path>,
    options: &ImportOptions,
) -> Result<MshImport<D>, MeshError> {
    let path = path.as_ref();
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| MeshError::Io {
        path: name.clone(),
        source,
    })?;
    // A binary file is not UTF-8; decoding it lossily still lets the header be checked
    // and rejected with a helpful message.
    let text = String::from_utf8_lossy(&bytes);
    parse_msh_with(&text, &name, options)
}

/// Parses the text of a Gmsh MSH 4.1 ASCII file into a mesh of dimension `D`.
///
/// `file_name` is only used in error messages. See [`read_msh`].
///
/// # Errors
///
/// [`MeshError::Parse`] with the 1-based line number and a message for every malformed,
/// truncated or unsupported input.
pub fn parse_msh<D: Dim>(text: &str, file_name: &str) -> Result<Mesh<D>, MeshError> {
    let import = parse_msh_with::<D>(text, file_name, &ImportOptions::default())?;
    Ok(print_warnings(import, file_name))
}

/// [`parse_msh`] with options, returning the warnings instead of printing them.
///
/// # Errors
///
/// As [`parse_msh`], and [`MeshError::InvalidParameter`] naming `coincident_rel_tol` when
/// it is not finite or outside `[0, 1e-3]`.
pub fn parse_msh_with<D: Dim>(
    text: &str,
    file_name: &str,
    options: &ImportOptions,
) -> Result<MshImport<D>, MeshError> {
    let tol = options.coincident_rel_tol;
    if !(0.0..=1e-3).contains(&tol) {
        return Err(MeshError::InvalidParameter {
            name: "coincident_rel_tol",
            value: tol,
            reason: "must be finite and in [0, 1e-3] (relative to the mesh extent)",
        });
    }
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let raw = parse_raw(text, file_name, D::D)?;
    build_mesh::<D>(raw, file_name, options)
}

// ---------------------------------------------------------------------------------------
// Raw file content
// ---------------------------------------------------------------------------------------

struct NodeRec {
    tag: u64,
    x: [f64; 3],
    line: usize,
}

struct ElemBlock {
    /// Entity dimension.
    dim: usize,
    /// Entity tag.
    entity: i32,
    /// Gmsh element type.
    etype: i32,
    /// Line of the block header.
    line: usize,
    /// Whether the elements were kept (a type the import uses).
    kept: bool,
    /// Nodes per kept element.
    npe: usize,
    /// Node tags of the kept elements, stride `npe`.
    nodes: Vec<u64>,
    /// Element tags of the kept elements.
    tags: Vec<u64>,
    /// Lines of the kept elements.
    lines: Vec<usize>,
}

#[derive(Default)]
struct RawMsh {
    names: HashMap<(usize, i32), String>,
    entities: HashMap<(usize, i32), Vec<i32>>,
    nodes: Vec<NodeRec>,
    nodes_line: Option<usize>,
    blocks: Vec<ElemBlock>,
    elements_line: Option<usize>,
    last_line: usize,
}

/// Name and node count of the Gmsh element types (first and second order, and points).
fn type_info(t: i32) -> Option<(&'static str, usize)> {
    Some(match t {
        1 => ("2-node line", 2),
        2 => ("3-node triangle", 3),
        3 => ("4-node quadrangle", 4),
        4 => ("4-node tetrahedron", 4),
        5 => ("8-node hexahedron", 8),
        6 => ("6-node prism", 6),
        7 => ("5-node pyramid", 5),
        8 => ("3-node second-order line", 3),
        9 => ("6-node second-order triangle", 6),
        10 => ("9-node second-order quadrangle", 9),
        11 => ("10-node second-order tetrahedron", 10),
        12 => ("27-node second-order hexahedron", 27),
        13 => ("18-node second-order prism", 18),
        14 => ("14-node second-order pyramid", 14),
        15 => ("1-node point", 1),
        16 => ("8-node second-order quadrangle", 8),
        17 => ("20-node second-order hexahedron", 20),
        18 => ("15-node second-order prism", 15),
        19 => ("13-node second-order pyramid", 13),
        _ => return None,
    })
}

fn type_name(t: i32) -> String {
    match type_info(t) {
        Some((name, _)) => format!("type {t} ({name})"),
        None => format!("type {t}"),
    }
}

/// The linear simplex type of an entity dimension: point, line, triangle, tetrahedron.
fn simplex_type(dim: usize) -> i32 {
    match dim {
        0 => 15,
        1 => 1,
        2 => 2,
        _ => 4,
    }
}

/// The non-simplex linear cell read in dimension `dim`: quadrangles (type 3) in 2D,
/// hexahedra (type 5) in 3D.
fn cell_type(dim: usize) -> i32 {
    if dim == 2 {
        3
    } else {
        5
    }
}

/// The cell kind of a top-dimension Gmsh element type.
fn kind_of(etype: i32) -> ElementKind {
    match etype {
        2 => ElementKind::Tri3,
        3 => ElementKind::Quad4,
        5 => ElementKind::Hex8,
        _ => ElementKind::Tet4,
    }
}

fn simplex_name(dim: usize) -> &'static str {
    if dim == 2 {
        "triangle"
    } else {
        "tetrahedron"
    }
}

fn simplex_plural(dim: usize) -> &'static str {
    if dim == 2 {
        "triangles"
    } else {
        "tetrahedra"
    }
}

/// Shortens a token or line quoted in an error message.
fn shorten(s: &str) -> String {
    const MAX: usize = 40;
    if s.chars().count() <= MAX {
        s.to_string()
    } else {
        let mut t: String = s.chars().take(MAX).collect();
        t.push_str("...");
        t
    }
}

fn parse_error(file: &str, line: usize, message: impl Into<String>) -> MeshError {
    MeshError::Parse {
        file: file.to_string(),
        line,
        message: message.into(),
    }
}

// ---------------------------------------------------------------------------------------
// Line reader
// ---------------------------------------------------------------------------------------

struct Reader<'a> {
    file: &'a str,
    lines: std::str::Lines<'a>,
    /// Number of the last line read (1-based), 0 before the first.
    line: usize,
}

/// One line (record) split into whitespace-separated tokens.
struct Record<'a> {
    file: &'a str,
    line: usize,
    text: &'a str,
    toks: std::str::SplitWhitespace<'a>,
}

impl<'a> Reader<'a> {
    fn new(text: &'a str, file: &'a str) -> Self {
        Reader {
            file,
            lines: text.lines(),
            line: 0,
        }
    }

    fn err(&self, line: usize, message: impl Into<String>) -> MeshError {
        parse_error(self.file, line, message)
    }

    fn eof_line(&self) -> usize {
        self.line.max(1)
    }

    /// Next non-blank line, trimmed, with its number.
    fn next_line(&mut self) -> Option<(usize, &'a str)> {
        for l in self.lines.by_ref() {
            self.line += 1;
            let t = l.trim();
            if !t.is_empty() {
                return Some((self.line, t));
            }
        }
        None
    }

    /// Next data record of a section; a section marker or the end of file is an error.
    fn record(&mut self, what: &str, section: &str, start: usize) -> Result<Record<'a>, MeshError> {
        match self.next_line() {
            None => Err(self.err(
                self.eof_line(),
                format!(
                    "unexpected end of file at line {} while reading {what} in ${section} \
                     (section starts at line {start}): the file is truncated",
                    self.eof_line()
                ),
            )),
            Some((ln, l)) if l.starts_with('$') => Err(self.err(
                ln,
                format!(
                    "expected {what} in ${section}, found '{}': the counts in ${section} do not match its data",
                    shorten(l)
                ),
            )),
            Some((ln, l)) => Ok(Record {
                file: self.file,
                line: ln,
                text: l,
                toks: l.split_whitespace(),
            }),
        }
    }

    /// Reads the `$EndSection` line.
    fn expect_end(&mut self, section: &str, start: usize) -> Result<(), MeshError> {
        match self.next_line() {
            None => Err(self.err(
                self.eof_line(),
                format!(
                    "missing $End{section}: unexpected end of file at line {} (${section} starts at line {start})",
                    self.eof_line()
                ),
            )),
            Some((_, l)) if l.strip_prefix("$End") == Some(section) => Ok(()),
            Some((ln, l)) => Err(self.err(
                ln,
                format!(
                    "expected $End{section}, found '{}': the counts in ${section} do not match its data",
                    shorten(l)
                ),
            )),
        }
    }

    /// Skips an unknown section up to its `$EndSection` line.
    fn skip_section(&mut self, section: &str, start: usize) -> Result<(), MeshError> {
        while let Some((_, l)) = self.next_line() {
            if l.strip_prefix("$End") == Some(section) {
                return Ok(());
            }
        }
        Err(self.err(
            self.eof_line(),
            format!(
                "missing $End{}: unexpected end of file at line {} (section starts at line {start})",
                shorten(section),
                self.eof_line()
            ),
        ))
    }
}

impl<'a> Record<'a> {
    fn err(&self, message: impl Into<String>) -> MeshError {
        parse_error(self.file, self.line, message)
    }

    fn next<T: FromStr>(&mut self, what: &str, expected: &str) -> Result<T, MeshError> {
        match self.toks.next() {
            None => Err(self.err(format!("missing {what}: the line ends early"))),
            Some(tok) => parse_token(tok, what, expected).map_err(|m| self.err(m)),
        }
    }

    fn usize(&mut self, what: &str) -> Result<usize, MeshError> {
        self.next(what, "a non-negative integer")
    }

    fn u64(&mut self, what: &str) -> Result<u64, MeshError> {
        self.next(what, "a non-negative integer")
    }

    fn i32(&mut self, what: &str) -> Result<i32, MeshError> {
        self.next(what, "an integer")
    }

    fn f64(&mut self, what: &str) -> Result<f64, MeshError> {
        self.next(what, "a number")
    }

    /// Checks that the record has no further token.
    fn finish(mut self, what: &str) -> Result<(), MeshError> {
        match self.toks.next() {
            None => Ok(()),
            Some(tok) => Err(self.err(format!(
                "unexpected extra value '{}' after {what}",
                shorten(tok)
            ))),
        }
    }
}

fn parse_token<T: FromStr>(tok: &str, what: &str, expected: &str) -> Result<T, String> {
    tok.parse()
        .map_err(|_| format!("invalid {what} '{}': expected {expected}", shorten(tok)))
}

/// Splits the first whitespace-separated token off `s`.
fn split_token(s: &str) -> Option<(&str, &str)> {
    let s = s.trim_start();
    if s.is_empty() {
        return None;
    }
    match s.find(char::is_whitespace) {
        Some(i) => Some((&s[..i], &s[i..])),
        None => Some((s, "")),
    }
}

// ---------------------------------------------------------------------------------------
// Sections
// ---------------------------------------------------------------------------------------

fn parse_raw(text: &str, file: &str, d: usize) -> Result<RawMsh, MeshError> {
    let mut r = Reader::new(text, file);
    let mut raw = RawMsh::default();
    match r.next_line() {
        Some((ln, "$MeshFormat")) => parse_format(&mut r, ln)?,
        Some((ln, l)) => {
            return Err(r.err(
                ln,
                format!(
                    "not a Gmsh MSH file: expected $MeshFormat, found '{}'; {EXPORT_HINT}",
                    shorten(l)
                ),
            ))
        }
        None => {
            return Err(r.err(
                1,
                format!("empty file: expected a Gmsh MSH 4.1 ASCII mesh; {EXPORT_HINT}"),
            ))
        }
    }
    let mut seen_names = false;
    let mut seen_entities = false;
    while let Some((ln, l)) = r.next_line() {
        let Some(name) = l.strip_prefix('$') else {
            return Err(r.err(
                ln,
                format!("expected a section start ($Name), found '{}'", shorten(l)),
            ));
        };
        let duplicate = |r: &Reader| r.err(ln, format!("duplicate ${name} section"));
        match name {
            "MeshFormat" => return Err(duplicate(&r)),
            "PhysicalNames" => {
                if std::mem::replace(&mut seen_names, true) {
                    return Err(duplicate(&r));
                }
                parse_physical_names(&mut r, ln, &mut raw)?;
            }
            "Entities" => {
                if std::mem::replace(&mut seen_entities, true) {
                    return Err(duplicate(&r));
                }
                parse_entities(&mut r, ln, &mut raw)?;
            }
            "Nodes" => {
                if raw.nodes_line.replace(ln).is_some() {
                    return Err(duplicate(&r));
                }
                parse_nodes(&mut r, ln, &mut raw)?;
            }
            "Elements" => {
                if raw.elements_line.replace(ln).is_some() {
                    return Err(duplicate(&r));
                }
                parse_elements(&mut r, ln, &mut raw, d)?;
            }
            _ if name.starts_with("End") || name.is_empty() => {
                return Err(r.err(
                    ln,
                    format!("'{}' without a matching section start", shorten(l)),
                ))
            }
            _ => r.skip_section(name, ln)?,
        }
    }
    raw.last_line = r.eof_line();
    Ok(raw)
}

fn parse_format(r: &mut Reader, start: usize) -> Result<(), MeshError> {
    let mut rec = r.record(
        "the format line (version file-type data-size)",
        "MeshFormat",
        start,
    )?;
    let version = rec.toks.next().unwrap_or("");
    if version != "4.1" {
        let what = if version.starts_with('2') {
            format!(
                "MSH version {} (legacy format 2) is not supported",
                shorten(version)
            )
        } else {
            format!("MSH version '{}' is not supported", shorten(version))
        };
        return Err(rec.err(format!("{what}; {EXPORT_HINT}")));
    }
    let file_type: i32 = rec.i32("file type")?;
    match file_type {
        0 => {}
        1 => return Err(rec.err(format!("binary MSH files are not supported; {EXPORT_HINT}"))),
        _ => {
            return Err(rec.err(format!(
                "invalid file type {file_type} (0 for ASCII, 1 for binary)"
            )))
        }
    }
    let _data_size: usize = rec.usize("data size")?;
    rec.finish("the data size")?;
    r.expect_end("MeshFormat", start)
}

fn parse_physical_names(r: &mut Reader, start: usize, raw: &mut RawMsh) -> Result<(), MeshError> {
    const S: &str = "PhysicalNames";
    let mut h = r.record("the number of physical names", S, start)?;
    let n = h.usize("number of physical names")?;
    h.finish("the number of physical names")?;
    for _ in 0..n {
        let rec = r.record("a physical name (dimension tag \"name\")", S, start)?;
        let mut rest = rec.text;
        let mut ints = [0i64; 2];
        for (k, what) in ["physical dimension", "physical tag"].iter().enumerate() {
            let Some((tok, tail)) = split_token(rest) else {
                return Err(rec.err(format!("missing {what}: the line ends early")));
            };
            ints[k] = parse_token::<i32>(tok, what, "an integer").map_err(|m| rec.err(m))? as i64;
            rest = tail;
        }
        let dim = ints[0];
        if !(0..=3).contains(&dim) {
            return Err(rec.err(format!("invalid physical dimension {dim}: expected 0 to 3")));
        }
        let tag = ints[1] as i32;
        let quoted = rest.trim();
        let name = quoted
            .strip_prefix('"')
            .and_then(|s| s.strip_suffix('"'))
            .filter(|s| !s.contains('"'))
            .ok_or_else(|| {
                rec.err(format!(
                    "expected a quoted physical name, found '{}'",
                    shorten(quoted)
                ))
            })?;
        if raw
            .names
            .insert((dim as usize, tag), name.to_string())
            .is_some()
        {
            return Err(rec.err(format!(
                "duplicate physical name for dimension {dim}, tag {tag}"
            )));
        }
    }
    r.expect_end(S, start)
}

fn parse_entities(r: &mut Reader, start: usize, raw: &mut RawMsh) -> Result<(), MeshError> {
    const S: &str = "Entities";
    let mut h = r.record(
        "the entity counts (numPoints numCurves numSurfaces numVolumes)",
        S,
        start,
    )?;
    let mut counts = [0usize; 4];
    for (c, what) in counts.iter_mut().zip([
        "number of points",
        "number of curves",
        "number of surfaces",
        "number of volumes",
    ]) {
        *c = h.usize(what)?;
    }
    h.finish("the number of volumes")?;
    for (dim, &count) in counts.iter().enumerate() {
        let what = [
            "a point entity",
            "a curve entity",
            "a surface entity",
            "a volume entity",
        ][dim];
        for _ in 0..count {
            let mut rec = r.record(what, S, start)?;
            let tag = rec.i32("entity tag")?;
            let n_coords = if dim == 0 { 3 } else { 6 };
            for _ in 0..n_coords {
                rec.f64("bounding box coordinate")?;
            }
            let n_phys = rec.usize("number of physical tags")?;
            let mut phys = Vec::new();
            for _ in 0..n_phys {
                phys.push(rec.i32("physical tag")?);
            }
            if dim > 0 {
                let n_bound = rec.usize("number of bounding entities")?;
                for _ in 0..n_bound {
                    rec.i32("bounding entity tag")?;
                }
            }
            let line = rec.line;
            rec.finish("the entity record")?;
            if raw.entities.insert((dim, tag), phys).is_some() {
                return Err(parse_error(
                    r.file,
                    line,
                    format!("duplicate entity of dimension {dim} with tag {tag}"),
                ));
            }
        }
    }
    r.expect_end(S, start)
}

fn parse_nodes(r: &mut Reader, start: usize, raw: &mut RawMsh) -> Result<(), MeshError> {
    const S: &str = "Nodes";
    let mut h = r.record(
        "the header (numEntityBlocks numNodes minNodeTag maxNodeTag)",
        S,
        start,
    )?;
    let n_blocks = h.usize("number of entity blocks")?;
    let n_nodes = h.usize("number of nodes")?;
    h.u64("minimum node tag")?;
    h.u64("maximum node tag")?;
    let header_line = h.line;
    h.finish("the maximum node tag")?;
    let mut total = 0usize;
    let mut tags = Vec::new();
    for _ in 0..n_blocks {
        let mut b = r.record(
            "a node block header (entityDim entityTag parametric numNodesInBlock)",
            S,
            start,
        )?;
        let edim = b.usize("entity dimension")?;
        if edim > 3 {
            return Err(b.err(format!("invalid entity dimension {edim}: expected 0 to 3")));
        }
        b.i32("entity tag")?;
        let parametric = b.usize("parametric flag")?;
        if parametric > 1 {
            return Err(b.err(format!(
                "invalid parametric flag {parametric}: expected 0 or 1"
            )));
        }
        let n = b.usize("number of nodes in the block")?;
        let block_line = b.line;
        b.finish("the number of nodes in the block")?;
        total = total
            .checked_add(n)
            .ok_or_else(|| parse_error(r.file, block_line, "the node count overflows"))?;
        tags.clear();
        for _ in 0..n {
            let mut t = r.record("a node tag", S, start)?;
            tags.push(t.u64("node tag")?);
            t.finish("the node tag")?;
        }
        let n_param = if parametric == 1 { edim } else { 0 };
        for &tag in &tags {
            let mut c = r.record("node coordinates (x y z)", S, start)?;
            let x = [
                c.f64("x coordinate")?,
                c.f64("y coordinate")?,
                c.f64("z coordinate")?,
            ];
            for _ in 0..n_param {
                c.f64("parametric coordinate")?;
            }
            let line = c.line;
            if x.iter().any(|v| !v.is_finite() || v.abs() > MAX_COORD) {
                return Err(c.err(format!(
                    "node {tag} has coordinates {x:?}: they must be finite and at most {MAX_COORD:e} in magnitude"
                )));
            }
            c.finish("the node coordinates")?;
            raw.nodes.push(NodeRec { tag, x, line });
        }
    }
    if total != n_nodes {
        return Err(parse_error(
            r.file,
            header_line,
            format!("the $Nodes header declares {n_nodes} nodes, but its blocks hold {total}"),
        ));
    }
    r.expect_end(S, start)
}

fn parse_elements(
    r: &mut Reader,
    start: usize,
    raw: &mut RawMsh,
    d: usize,
) -> Result<(), MeshError> {
    const S: &str = "Elements";
    let mut h = r.record(
        "the header (numEntityBlocks numElements minElementTag maxElementTag)",
        S,
        start,
    )?;
    let n_blocks = h.usize("number of entity blocks")?;
    let n_elems = h.usize("number of elements")?;
    h.u64("minimum element tag")?;
    h.u64("maximum element tag")?;
    let header_line = h.line;
    h.finish("the maximum element tag")?;
    let top = simplex_type(d);
    let mut total = 0usize;
    for _ in 0..n_blocks {
        let mut b = r.record(
            "an element block header (entityDim entityTag elementType numElementsInBlock)",
            S,
            start,
        )?;
        let edim = b.usize("entity dimension")?;
        if edim > 3 {
            return Err(b.err(format!("invalid entity dimension {edim}: expected 0 to 3")));
        }
        let entity = b.i32("entity tag")?;
        let etype = b.i32("element type")?;
        let n = b.usize("number of elements in the block")?;
        let line = b.line;
        if edim > d {
            return Err(b.err(format!(
                "{edim}D elements ({}) in entity {entity}: this is a {edim}D mesh, read it as Dim{edim}",
                type_name(etype)
            )));
        }
        if edim == d && etype != top && etype != cell_type(d) {
            return Err(b.err(format!(
                "element {} is not supported: a {d}D mesh must consist of linear {} (type {top}) \
                 or {} (type {}) only; remesh with first-order elements (Mesh.ElementOrder = 1)",
                type_name(etype),
                simplex_plural(d),
                if d == 2 { "quadrangles" } else { "hexahedra" },
                cell_type(d)
            )));
        }
        b.finish("the number of elements in the block")?;
        total = total
            .checked_add(n)
            .ok_or_else(|| parse_error(r.file, line, "the element count overflows"))?;
        // Top-dimension quadrangles/hexahedra, and quadrangle faces of a 3D mesh.
        let kept = etype == simplex_type(edim)
            || (edim == d && etype == cell_type(d))
            || (d == 3 && edim == 2 && etype == 3);
        let npe = if kept {
            type_info(etype).map_or(0, |t| t.1)
        } else {
            0
        };
        let mut block = ElemBlock {
            dim: edim,
            entity,
            etype,
            line,
            kept,
            npe,
            nodes: Vec::new(),
            tags: Vec::new(),
            lines: Vec::new(),
        };
        for _ in 0..n {
            let mut e = r.record("an element (elementTag nodeTag ...)", S, start)?;
            let tag = e.u64("element tag")?;
            if kept {
                for _ in 0..npe {
                    match e.toks.next() {
                        None => {
                            return Err(e.err(format!(
                                "element {tag} has too few node tags: a {} needs {npe}",
                                type_name(etype)
                            )))
                        }
                        Some(tok) => block.nodes.push(
                            parse_token(tok, "node tag", "a non-negative integer")
                                .map_err(|m| e.err(m))?,
                        ),
                    }
                }
                block.tags.push(tag);
                block.lines.push(e.line);
                e.finish("the node tags of the element")?;
            } else {
                let mut count = 0usize;
                while let Some(tok) = e.toks.next() {
                    parse_token::<u64>(tok, "node tag", "a non-negative integer")
                        .map_err(|m| e.err(m))?;
                    count += 1;
                }
                if let Some((_, expected)) = type_info(etype) {
                    if count != expected {
                        return Err(e.err(format!(
                            "element {tag} has {count} node tags, but a {} has {expected}",
                            type_name(etype)
                        )));
                    }
                }
            }
        }
        raw.blocks.push(block);
    }
    if total != n_elems {
        return Err(parse_error(
            r.file,
            header_line,
            format!(
                "the $Elements header declares {n_elems} elements, but its blocks hold {total}"
            ),
        ));
    }
    r.expect_end(S, start)
}

// ---------------------------------------------------------------------------------------
// Mesh and groups
// ---------------------------------------------------------------------------------------

fn build_mesh<D: Dim>(
    raw: RawMsh,
    file: &str,
    options: &ImportOptions,
) -> Result<MshImport<D>, MeshError> {
    let d = D::D;
    let err = |line: usize, message: String| parse_error(file, line, message);
    let Some(elements_line) = raw.elements_line else {
        return Err(err(raw.last_line, "missing $Elements section".into()));
    };
    if raw.nodes_line.is_none() {
        return Err(err(raw.last_line, "missing $Nodes section".into()));
    }

    // Nodes in increasing tag order.
    let mut nodes = raw.nodes;
    nodes.sort_by_key(|n| n.tag);
    if let Some(w) = nodes.windows(2).find(|w| w[0].tag == w[1].tag) {
        return Err(err(
            w[0].line.max(w[1].line),
            format!("duplicate node tag {}", w[0].tag),
        ));
    }
    let find = |tag: u64| nodes.binary_search_by_key(&tag, |n| n.tag).ok();

    // Top-dimension elements.
    let mut used = vec![false; nodes.len()];
    let mut conn_sorted = Vec::new();
    let mut elem_lines = Vec::new();
    let mut elem_tags = Vec::new();
    let mut kinds = Vec::new();
    for b in raw.blocks.iter().filter(|b| b.kept && b.dim == d) {
        for (k, tags) in b.nodes.chunks_exact(b.npe).enumerate() {
            kinds.push(kind_of(b.etype));
            for &t in tags {
                let i = find(t).ok_or_else(|| {
                    err(
                        b.lines[k],
                        format!("element {} refers to unknown node tag {t}", b.tags[k]),
                    )
                })?;
                used[i] = true;
                conn_sorted.push(i);
            }
            elem_lines.push(b.lines[k]);
            elem_tags.push(b.tags[k]);
        }
    }
    if conn_sorted.is_empty() {
        let hint = if d == 3 {
            " (is this a 2D mesh? read it as Dim2)"
        } else {
            ""
        };
        return Err(err(
            elements_line,
            format!(
                "no {} (element type {}) in {d}D entities: the file holds no {d}D mesh{hint}",
                simplex_plural(d),
                simplex_type(d)
            ),
        ));
    }

    // Coincident nodes: warn, or merge into the node of lowest tag.
    let points: Vec<[f64; 3]> = nodes.iter().map(|n| n.x).collect();
    let extent = (0..d)
        .map(|k| {
            let it = points
                .iter()
                .zip(&used)
                .filter(|(_, &u)| u)
                .map(|(p, _)| p[k]);
            it.clone().fold(f64::NEG_INFINITY, f64::max) - it.fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max);
    let tol = options.coincident_rel_tol * extent;
    let rep = coincident::representatives(&points, &used, d, tol);
    let mut warnings = Vec::new();
    let dup: Vec<usize> = (0..nodes.len()).filter(|&i| rep[i] != i).collect();
    let mut merged_nodes = 0;
    if let Some(&first) = dup.first() {
        if options.merge_coincident {
            for i in conn_sorted.iter_mut() {
                *i = rep[*i];
            }
            for &i in &dup {
                used[i] = false;
            }
            merged_nodes = dup.len();
        } else {
            warnings.push(ImportWarning::CoincidentNodes {
                count: dup.len(),
                tags: (nodes[rep[first]].tag, nodes[first].tag),
                position: nodes[first].x,
                line: nodes[first].line,
                tol,
            });
        }
    }

    // Compact renumbering in node-tag order.
    let mut new_index = vec![u32::MAX; nodes.len()];
    let mut node_tags = Vec::new();
    let mut coords = Vec::new();
    for (i, n) in nodes.iter().enumerate() {
        if used[i] {
            if node_tags.len() >= u32::MAX as usize {
                return Err(err(n.line, "too many nodes for 32-bit indices".into()));
            }
            new_index[i] = node_tags.len() as u32;
            node_tags.push(n.tag);
            coords.extend_from_slice(&n.x[..d]);
        }
    }
    if d == 2 {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in coords.chunks_exact(2) {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let size = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        if let Some(n) = nodes
            .iter()
            .zip(&used)
            .find(|(n, &u)| u && n.x[2].abs() > Z_REL_TOL * size)
            .map(|(n, _)| n)
        {
            return Err(err(
                n.line,
                format!(
                    "node {} has z = {:e}, but a 2D mesh must lie in the plane z = 0 (mesh size {size:e})",
                    n.tag, n.x[2]
                ),
            ));
        }
    }
    if merged_nodes > 0 {
        for &i in &dup {
            new_index[i] = new_index[rep[i]];
        }
    }
    let conn: Vec<u32> = conn_sorted.iter().map(|&i| new_index[i]).collect();
    let last_line = raw.last_line;
    let built = if kinds.iter().all(|k| k.is_simplex()) {
        Mesh::<D>::new_reoriented(coords, conn)
    } else {
        Mesh::<D>::from_cells_reoriented(coords, kinds, conn)
    };
    let mut mesh =
        built.map_err(|e| mesh_error(e, file, last_line, &elem_lines, &elem_tags, &node_tags))?;

    // Physical groups.
    let name_of = |dim: usize, tag: i32| {
        raw.names
            .get(&(dim, tag))
            .cloned()
            .unwrap_or_else(|| format!("physical_{tag}"))
    };
    let mut node_groups: BTreeMap<String, Vec<u32>> = BTreeMap::new();
    let mut elem_groups: BTreeMap<String, Vec<u32>> = BTreeMap::new();
    let mut face_groups: BTreeMap<String, Vec<u32>> = BTreeMap::new();
    let mut line_groups: BTreeMap<String, Vec<[u32; 2]>> = BTreeMap::new();
    // Named physical groups exist even when they hold no element.
    for (&(dim, _), name) in &raw.names {
        if dim > d {
            continue;
        }
        node_groups.entry(name.clone()).or_default();
        if dim == d {
            elem_groups.entry(name.clone()).or_default();
        } else if dim + 1 == d {
            face_groups.entry(name.clone()).or_default();
        }
    }
    let no_phys = Vec::new();
    let phys_of = |b: &ElemBlock| raw.entities.get(&(b.dim, b.entity)).unwrap_or(&no_phys);

    let mut face_map: HashMap<[u32; 3], u32> = HashMap::new();
    let needs_faces = raw
        .blocks
        .iter()
        .any(|b| b.kept && b.dim + 1 == d && !phys_of(b).is_empty());
    if needs_faces {
        let npf = D::NODES_PER_FACE;
        for (f, fnodes) in mesh.faces().nodes.chunks_exact(npf).enumerate() {
            let mut key = [u32::MAX; 3];
            key[..npf].copy_from_slice(fnodes);
            key[..npf].sort_unstable();
            face_map.insert(key, f as u32);
        }
    }

    let mut first_cell = 0usize;
    for b in &raw.blocks {
        let phys = phys_of(b);
        if b.dim == d {
            let cells = first_cell..first_cell + b.tags.len();
            for &p in phys {
                let name = name_of(b.dim, p);
                let elems = elem_groups.entry(name.clone()).or_default();
                for c in cells.clone() {
                    elems.extend(mesh.cell_elements(c).map(|e| e as u32));
                }
                let nodes = node_groups.entry(name).or_default();
                for c in cells.clone() {
                    nodes.extend_from_slice(mesh.cell_nodes(c));
                }
            }
            first_cell = cells.end;
            continue;
        }
        let Some(&p0) = phys.first() else { continue };
        if !b.kept {
            return Err(err(
                b.line,
                format!(
                    "element {} in physical group '{}' is not supported: only linear elements \
                     (points, 2-node lines, 3-node triangles) can form lower-dimensional groups",
                    type_name(b.etype),
                    name_of(b.dim, p0)
                ),
            ));
        }
        let is_face = b.dim + 1 == d;
        for (k, tags) in b.nodes.chunks_exact(b.npe.max(1)).enumerate() {
            let (line, etag) = (b.lines[k], b.tags[k]);
            let mut key = [u32::MAX; 4];
            for (j, &t) in tags.iter().enumerate() {
                let i = find(t).ok_or_else(|| {
                    err(
                        line,
                        format!("element {etag} refers to unknown node tag {t}"),
                    )
                })?;
                if new_index[i] == u32::MAX {
                    return Err(err(
                        line,
                        format!(
                            "element {etag} (physical group '{}') uses node {t}, which belongs to no {} of the mesh",
                            name_of(b.dim, p0),
                            simplex_name(d)
                        ),
                    ));
                }
                key[j] = new_index[i];
            }
            let faces = if is_face && tags.len() == 4 {
                // A hexahedron face: the two triangles of either diagonal.
                let q = key;
                let tri = |a: u32, b: u32, c: u32| {
                    let mut k = [a, b, c];
                    k.sort_unstable();
                    face_map.get(&k).copied()
                };
                let pair = match (tri(q[0], q[1], q[2]), tri(q[0], q[2], q[3])) {
                    (Some(f), Some(g)) => Some([f, g]),
                    _ => tri(q[0], q[1], q[3])
                        .zip(tri(q[1], q[2], q[3]))
                        .map(|(f, g)| [f, g]),
                };
                let pair = pair.ok_or_else(|| {
                    err(
                        line,
                        format!(
                            "element {etag} (physical group '{}', nodes {tags:?}) is not a face of any hexahedron of the mesh",
                            name_of(b.dim, p0)
                        ),
                    )
                })?;
                pair.to_vec()
            } else if is_face {
                let mut k3 = [key[0], key[1], key[2]];
                k3[..tags.len()].sort_unstable();
                let f = face_map.get(&k3).copied().ok_or_else(|| {
                    err(
                        line,
                        format!(
                            "element {etag} (physical group '{}', nodes {tags:?}) is not a face of any {} of the mesh",
                            name_of(b.dim, p0),
                            simplex_name(d)
                        ),
                    )
                })?;
                vec![f]
            } else {
                Vec::new()
            };
            for &p in phys {
                let name = name_of(b.dim, p);
                if b.dim == 1 && tags.len() == 2 {
                    line_groups
                        .entry(name.clone())
                        .or_default()
                        .push([key[0], key[1]]);
                }
                face_groups
                    .entry(name.clone())
                    .or_default()
                    .extend_from_slice(&faces);
                node_groups
                    .entry(name)
                    .or_default()
                    .extend(key.iter().copied().filter(|&v| v != u32::MAX));
            }
        }
    }

    let group_err = |e: MeshError| parse_error(file, last_line, e.to_string());
    for (name, v) in node_groups {
        mesh.add_node_group(name, v).map_err(group_err)?;
    }
    for (name, v) in elem_groups {
        mesh.add_element_group(name, v).map_err(group_err)?;
    }
    for (name, v) in face_groups {
        mesh.add_face_group(name, v).map_err(group_err)?;
    }
    Ok(MshImport {
        mesh,
        warnings,
        merged_nodes,
        lines: line_groups,
    })
}

/// Turns a mesh check failure into a parse error at the line of the offending element,
/// with Gmsh element and node tags instead of internal indices.
fn mesh_error(
    e: MeshError,
    file: &str,
    last_line: usize,
    elem_lines: &[usize],
    elem_tags: &[u64],
    node_tags: &[u64],
) -> MeshError {
    let line_of = |el: usize| elem_lines.get(el).copied().unwrap_or(last_line);
    let tag_of = |el: usize| elem_tags.get(el).copied().unwrap_or(0);
    let node_tag = |n: u32| node_tags.get(n as usize).copied().unwrap_or(0);
    let (line, message) = match &e {
        MeshError::RepeatedNode { element, node } => (
            line_of(*element),
            format!("element {} repeats node {}", tag_of(*element), node_tag(*node)),
        ),
        MeshError::DegenerateElement {
            element,
            measure,
            threshold,
            measure_name,
        } => (
            line_of(*element),
            format!(
                "element {} is degenerate ({measure_name} {measure:e}, below {threshold:e})",
                tag_of(*element)
            ),
        ),
        MeshError::NonManifoldFace { nodes, element } => (
            line_of(*element),
            format!(
                "element {} is the third element on the face with nodes {:?}: the mesh is not manifold",
                tag_of(*element),
                nodes.iter().map(|&n| node_tag(n)).collect::<Vec<_>>()
            ),
        ),
        MeshError::BadCell { cell, kind, reason } => (
            line_of(*cell),
            format!("element {} ({kind:?}) {reason}", tag_of(*cell)),
        ),
        MeshError::InvertedElement { element, .. } | MeshError::BadNodeIndex { element, .. } => {
            (line_of(*element), format!("element {}: {e}", tag_of(*element)))
        }
        _ => (last_line, e.to_string()),
    };
    parse_error(file, line, message)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Dim2, Dim3};
    use proptest::prelude::*;

    fn data(name: &str) -> String {
        format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"))
    }

    fn square_text() -> String {
        std::fs::read_to_string(data("square.msh")).unwrap()
    }

    /// Parses and expects a parse error; returns (line, message).
    fn parse_err<D: Dim>(text: &str) -> (usize, String) {
        match parse_msh::<D>(text, "test.msh") {
            Err(MeshError::Parse {
                line,
                message,
                file,
            }) => {
                assert_eq!(file, "test.msh");
                (line, message)
            }
            Err(e) => panic!("expected a parse error, got {e}"),
            Ok(_) => panic!("expected a parse error, got a mesh"),
        }
    }

    /// Line number (1-based) of the first line equal to `l`.
    fn line_of(text: &str, l: &str) -> usize {
        text.lines().position(|x| x.trim() == l).unwrap() + 1
    }

    /// Two triangles of the unit square whose shared diagonal has duplicate nodes 5 and 6
    /// (at the places of nodes 2 and 3): an unmerged, cut mesh.
    pub(crate) const CUT_SQUARE: &str = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n\
        $Nodes\n1 6 1 6\n2 1 0 6\n1\n2\n3\n4\n5\n6\n\
        0 0 0\n1 0 0\n0 1 0\n1 1 0\n1 0 0\n0 1 0\n$EndNodes\n\
        $Elements\n1 2 1 2\n2 1 2 2\n1 1 2 3\n2 5 4 6\n$EndElements\n";

    #[test]
    fn byte_order_mark_is_skipped() {
        let with_bom = format!("\u{feff}{}", square_text());
        let m = parse_msh::<Dim2>(&with_bom, "bom.msh").unwrap();
        assert_eq!(m.n_elements(), 4);
    }

    #[test]
    fn coincident_nodes_warn_or_merge() {
        let opts = ImportOptions::default();
        let cut = parse_msh_with::<Dim2>(CUT_SQUARE, "cut.msh", &opts).unwrap();
        assert_eq!(cut.mesh.n_nodes(), 6);
        assert_eq!(cut.mesh.faces().boundary.len(), 6, "cut: no interior face");
        assert_eq!(cut.warnings.len(), 1);
        let w = cut.warnings[0].to_string();
        assert!(
            w.contains("2 node(s) coincide") && w.contains("nodes 2 and 5"),
            "{w}"
        );
        assert!(w.contains("merge_coincident"), "{w}");
        let merged = ImportOptions {
            merge_coincident: true,
            ..ImportOptions::default()
        };
        let joined = parse_msh_with::<Dim2>(CUT_SQUARE, "cut.msh", &merged).unwrap();
        assert!(joined.warnings.is_empty());
        assert_eq!(joined.merged_nodes, 2);
        assert_eq!(joined.mesh.n_nodes(), 4);
        assert_eq!(joined.mesh.faces().len(), 5);
        assert_eq!(joined.mesh.faces().boundary.len(), 4);
        // A clean file gives no warning.
        let clean = parse_msh_with::<Dim2>(&square_text(), "sq.msh", &opts).unwrap();
        assert!(clean.warnings.is_empty());
        let bad = ImportOptions {
            coincident_rel_tol: f64::NAN,
            ..ImportOptions::default()
        };
        let e = parse_msh_with::<Dim2>(CUT_SQUARE, "cut.msh", &bad).unwrap_err();
        assert!(e.to_string().contains("coincident_rel_tol"), "{e}");
    }

    #[test]
    fn square_2d_counts_and_groups() {
        let m = read_msh::<Dim2>(data("square.msh")).unwrap();
        // Node tag 9 is used by no triangle and is dropped; tags 1, 2, 3, 4, 6 -> 0..5.
        assert_eq!(m.n_nodes(), 5);
        assert_eq!(m.n_elements(), 4);
        assert_eq!(m.faces().len(), 8);
        assert_eq!(m.faces().boundary.len(), 4);
        assert_eq!(m.node(4), &[0.5, 0.5]);
        assert_eq!(m.node(3), &[0.0, 1.0]);
        let area: f64 = (0..4).map(|e| m.element_measure(e)).sum();
        assert!((area - 1.0).abs() < 1e-14);
        // Element tag 10 was clockwise and has been reoriented.
        assert!((0..4).all(|e| m.element_measure(e) > 0.0));

        let g = m.groups();
        assert_eq!(g.elements["rock"], vec![0, 1, 2, 3]);
        assert_eq!(g.nodes["rock"], vec![0, 1, 2, 3, 4]);
        assert_eq!(g.nodes["left"], vec![0, 3]);
        assert_eq!(g.nodes["right"], vec![1, 2]);
        assert_eq!(g.nodes["origin"], vec![0]);
        assert_eq!(g.faces["left"].len(), 1);
        assert_eq!(g.faces["right"].len(), 1);
        assert_eq!(m.nodes_of_faces(&g.faces["left"]), vec![0, 3]);
        assert_eq!(m.nodes_of_faces(&g.faces["right"]), vec![1, 2]);
        let f = g.faces["left"][0] as usize;
        assert!(m.faces().boundary.contains(&(f as u32)));
        let mut n = [0.0; 2];
        m.face_measure_normal(f, &mut n);
        assert!((n[0] + 1.0).abs() < 1e-14, "left face normal {n:?}");
        assert!(!g.faces.contains_key("rock"));
        assert!(!g.elements.contains_key("left"));
        // The curve groups' lines, as mesh node pairs; points and surfaces have none.
        let lines = read_msh_with::<Dim2>(data("square.msh"), &ImportOptions::default())
            .unwrap()
            .lines;
        let sorted = |v: &[[u32; 2]]| -> Vec<[u32; 2]> {
            v.iter().map(|&[a, b]| [a.min(b), a.max(b)]).collect()
        };
        assert_eq!(sorted(&lines["left"]), vec![[0, 3]]);
        assert_eq!(sorted(&lines["right"]), vec![[1, 2]]);
        assert!(!lines.contains_key("origin") && !lines.contains_key("rock"));
    }

    #[test]
    fn pyramid_3d_counts_and_groups() {
        let m = read_msh::<Dim3>(data("pyramid.msh")).unwrap();
        assert_eq!(m.n_nodes(), 6);
        assert_eq!(m.n_elements(), 3);
        assert!((0..3).all(|e| m.element_measure(e) > 0.0));
        let vol: f64 = (0..3).map(|e| m.element_measure(e)).sum();
        assert!((vol - (1.0 / 3.0 + 0.125)).abs() < 1e-12, "{vol}");
        let g = m.groups();
        assert_eq!(g.elements["rock"], vec![0, 1, 2]);
        assert_eq!(g.faces["base"].len(), 2);
        assert_eq!(g.nodes["base"], vec![0, 1, 2, 3]);
        assert_eq!(m.nodes_of_faces(&g.faces["base"]), vec![0, 1, 2, 3]);
        for &f in &g.faces["base"] {
            let mut n = [0.0; 3];
            let a = m.face_measure_normal(f as usize, &mut n);
            assert!((a - 0.5).abs() < 1e-14);
            assert!((n[2] + 1.0).abs() < 1e-14, "base normal {n:?}");
        }
    }

    #[test]
    fn truncated_file_is_a_parse_error_naming_the_line() {
        let text = std::fs::read_to_string(data("square_truncated.msh")).unwrap();
        let n_lines = text.lines().count();
        let err = read_msh::<Dim2>(data("square_truncated.msh")).unwrap_err();
        let MeshError::Parse {
            line,
            ref message,
            ref file,
        } = err
        else {
            panic!("{err}")
        };
        assert_eq!(line, n_lines);
        assert!(file.ends_with("square_truncated.msh"));
        assert!(message.contains("end of file"), "{message}");
        assert!(message.contains(&format!("line {n_lines}")), "{message}");
        assert!(message.contains("$Elements"), "{message}");
        assert!(err.to_string().contains(&format!(":{n_lines}: ")), "{err}");
    }

    #[test]
    fn missing_file_is_an_io_error() {
        let err = read_msh::<Dim2>(data("does_not_exist.msh")).unwrap_err();
        assert!(matches!(err, MeshError::Io { .. }), "{err}");
    }

    #[test]
    fn wrong_dimension() {
        let (_, msg) = parse_err::<Dim2>(&std::fs::read_to_string(data("pyramid.msh")).unwrap());
        assert!(msg.contains("Dim3"), "{msg}");
        let (_, msg) = parse_err::<Dim3>(&square_text());
        assert!(
            msg.contains("no tetrahedra") || msg.contains("Dim2"),
            "{msg}"
        );
    }

    #[test]
    fn legacy_and_binary_formats_are_rejected_with_export_hint() {
        let t = square_text();
        let (line, msg) = parse_err::<Dim2>(&t.replacen("4.1 0 8", "2.2 0 8", 1));
        assert_eq!(line, 2);
        assert!(
            msg.contains("2.2") && msg.contains("msh41") && msg.contains("Mesh.Binary = 0"),
            "{msg}"
        );
        let (line, msg) = parse_err::<Dim2>(&t.replacen("4.1 0 8", "4.1 1 8", 1));
        assert_eq!(line, 2);
        assert!(msg.contains("binary") && msg.contains("msh41"), "{msg}");
        let (line, msg) = parse_err::<Dim2>("hello\n");
        assert_eq!(line, 1);
        assert!(msg.contains("$MeshFormat"), "{msg}");
        let (_, msg) = parse_err::<Dim2>("");
        assert!(msg.contains("empty"), "{msg}");
    }

    /// Two hexahedra side by side (the second listed inverted) with a physical volume
    /// and a physical quadrangle face.
    fn two_hexes() -> String {
        let tag = |i: usize, j: usize, k: usize| 1 + i + 3 * (j + 2 * k);
        let mut t = String::from(
            "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n2 1 \"xmin\"\n3 2 \"rock\"\n$EndPhysicalNames\n\
             $Entities\n0 0 1 1\n1 0 0 0 0 1 1 1 1 0\n1 0 0 0 2 1 1 1 2 0\n$EndEntities\n\
             $Nodes\n1 12 1 12\n3 1 0 12\n",
        );
        for n in 1..=12 {
            t += &format!("{n}\n");
        }
        for k in 0..2 {
            for j in 0..2 {
                for i in 0..3 {
                    t += &format!("{i} {j} {k}\n");
                }
            }
        }
        t += "$EndNodes\n$Elements\n2 3 1 3\n2 1 3 1\n";
        t += &format!(
            "1 {} {} {} {}\n",
            tag(0, 0, 0),
            tag(0, 1, 0),
            tag(0, 1, 1),
            tag(0, 0, 1)
        );
        t += "3 1 5 2\n";
        let hex = |i: usize| {
            [
                tag(i, 0, 0),
                tag(i + 1, 0, 0),
                tag(i + 1, 1, 0),
                tag(i, 1, 0),
                tag(i, 0, 1),
                tag(i + 1, 0, 1),
                tag(i + 1, 1, 1),
                tag(i, 1, 1),
            ]
        };
        let mut h1 = hex(1);
        h1.swap(1, 3);
        h1.swap(5, 7);
        for (e, h) in [(2, hex(0)), (3, h1)] {
            t += &format!("{e} {}\n", h.map(|v| v.to_string()).join(" "));
        }
        t + "$EndElements\n"
    }

    #[test]
    fn hexahedra_and_their_quadrangle_faces_are_read() {
        let m = parse_msh::<Dim3>(&two_hexes(), "hex.msh").unwrap();
        assert_eq!(m.n_cells(), 2);
        assert!((0..2).all(|c| m.cell_kind(c) == ElementKind::Hex8));
        let vol: f64 = (0..m.n_elements()).map(|e| m.element_measure(e)).sum();
        assert!((vol - 2.0).abs() < 1e-12, "{vol}");
        assert_eq!(m.groups().elements["rock"].len(), m.n_elements());
        let xmin = &m.groups().faces["xmin"];
        assert_eq!(xmin.len(), 2);
        let mut c = [0.0; 3];
        for &f in xmin {
            m.face_centroid(f as usize, &mut c);
            assert!(c[0].abs() < 1e-12 && m.faces().neighbor[f as usize] == crate::NO_NEIGHBOR);
        }
        // A hexahedron with a node moved through its opposite face is twisted.
        let bad = two_hexes().replacen("1 0 1\n", "1 0 -2\n", 1);
        let (_, msg) = parse_err::<Dim3>(&bad);
        assert!(msg.contains("Hex8") && msg.contains("element 2"), "{msg}");
    }

    #[test]
    fn mixed_triangles_and_quadrangles_are_read() {
        let t = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 1 0\n1 0 0 0 2 1 0 0 0\n$EndEntities\n\
                 $Nodes\n1 6 1 6\n2 1 0 6\n1\n2\n3\n4\n5\n6\n0 0 0\n1 0 0\n2 0 0\n0 1 0\n1 1 0\n2 1 0\n$EndNodes\n\
                 $Elements\n2 3 1 3\n2 1 3 1\n1 1 2 5 4\n2 1 2 2\n2 2 3 6\n3 2 6 5\n$EndElements\n";
        let m = parse_msh::<Dim2>(t, "mixed.msh").unwrap();
        let kinds: Vec<ElementKind> = (0..m.n_cells()).map(|c| m.cell_kind(c)).collect();
        assert_eq!(
            kinds,
            [ElementKind::Quad4, ElementKind::Tri3, ElementKind::Tri3]
        );
        assert_eq!(m.n_elements(), 4);
    }

    #[test]
    fn unsupported_top_dimension_types_name_type_and_line() {
        let t = square_text();
        // The triangle block declared as quadrangles (which are read): its first
        // element has too few nodes.
        let quad = t.replacen("2 1 2 4\n", "2 1 3 4\n", 1);
        let (line, msg) = parse_err::<Dim2>(&quad);
        assert_eq!(line, line_of(&t, "2 1 2 4") + 1);
        assert!(
            msg.contains("too few node tags") && msg.contains("quadrangle"),
            "{msg}"
        );
        let second = t.replacen("2 1 2 4\n", "2 1 9 4\n", 1);
        let (_, msg) = parse_err::<Dim2>(&second);
        assert!(
            msg.contains("type 9") && msg.contains("second-order"),
            "{msg}"
        );
    }

    #[test]
    fn malformed_inputs_name_their_line() {
        let t = square_text();
        // Non-numeric token.
        let (line, msg) = parse_err::<Dim2>(&t.replacen("0.5 0.5 0", "0.5 x 0", 1));
        assert_eq!(line, line_of(&t, "0.5 0.5 0"));
        assert!(msg.contains("'x'") && msg.contains("y coordinate"), "{msg}");
        // Unknown node tag in a triangle.
        let (line, msg) = parse_err::<Dim2>(&t.replacen("8 2 3 6", "8 2 3 7", 1));
        assert_eq!(line, line_of(&t, "8 2 3 6"));
        assert!(msg.contains("unknown node tag 7"), "{msg}");
        // Node count in the header does not match the blocks.
        let (line, msg) = parse_err::<Dim2>(&t.replacen("6 6 1 9", "6 7 1 9", 1));
        assert_eq!(line, line_of(&t, "6 6 1 9"));
        assert!(msg.contains("7 nodes"), "{msg}");
        // Block count too large: runs into $EndElements.
        let (line, msg) = parse_err::<Dim2>(&t.replacen("7 10 1 10", "8 10 1 10", 1));
        assert_eq!(line, line_of(&t, "$EndElements"));
        assert!(msg.contains("do not match"), "{msg}");
        // Block count too small: the last block is left over.
        let (line, msg) = parse_err::<Dim2>(&t.replacen("7 10 1 10", "6 6 1 10", 1));
        assert_eq!(line, line_of(&t, "2 1 2 4"));
        assert!(msg.contains("$EndElements"), "{msg}");
        // Missing end marker.
        let (line, msg) = parse_err::<Dim2>(&t.replacen("$EndNodeData", "", 1));
        assert_eq!(line, t.lines().count());
        assert!(msg.contains("$EndNodeData"), "{msg}");
        // Too few node tags for a triangle.
        let (line, msg) = parse_err::<Dim2>(&t.replacen("9 3 4 6", "9 3 4", 1));
        assert_eq!(line, line_of(&t, "9 3 4 6"));
        assert!(msg.contains("too few node tags"), "{msg}");
        // Extra value.
        let (line, msg) = parse_err::<Dim2>(&t.replacen("9 3 4 6", "9 3 4 6 7", 1));
        assert_eq!(line, line_of(&t, "9 3 4 6"));
        assert!(msg.contains("extra value '7'"), "{msg}");
        // Duplicate node tag.
        let dup = t.replacen("0 5 0 1\n9\n", "0 5 0 1\n6\n", 1);
        let (_, msg) = parse_err::<Dim2>(&dup);
        assert!(msg.contains("duplicate node tag 6"), "{msg}");
        // Unquoted physical name.
        let (line, msg) = parse_err::<Dim2>(&t.replacen("\"rock\"", "rock", 1));
        assert_eq!(line, line_of(&t, "2 3 \"rock\""));
        assert!(msg.contains("quoted"), "{msg}");
        // Stray content between sections.
        let (_, msg) = parse_err::<Dim2>(&t.replacen("$EndEntities\n", "$EndEntities\nfoo\n", 1));
        assert!(msg.contains("'foo'"), "{msg}");
        // Non-finite coordinate.
        let (_, msg) = parse_err::<Dim2>(&t.replacen("0.5 0.5 0", "0.5 inf 0", 1));
        assert!(msg.contains("finite"), "{msg}");
    }

    #[test]
    fn nonzero_z_in_2d_is_an_error() {
        let t = square_text();
        let (line, msg) = parse_err::<Dim2>(&t.replacen("0.5 0.5 0", "0.5 0.5 0.01", 1));
        assert_eq!(line, line_of(&t, "0.5 0.5 0"));
        assert!(msg.contains("node 6") && msg.contains("z = "), "{msg}");
        // Round-off is tolerated.
        let m = parse_msh::<Dim2>(&t.replacen("0.5 0.5 0", "0.5 0.5 1e-17", 1), "t").unwrap();
        assert_eq!(m.n_nodes(), 5);
    }

    #[test]
    fn boundary_element_that_is_no_face_is_an_error() {
        let t = square_text();
        // The "left" line now joins two opposite corners (a diagonal, not an edge).
        let (line, msg) = parse_err::<Dim2>(&t.replacen("6 4 1", "6 4 2", 1));
        assert_eq!(line, line_of(&t, "6 4 1"));
        assert!(
            msg.contains("not a face") && msg.contains("'left'"),
            "{msg}"
        );
        // A physical point on a node used by no triangle.
        let p = t.replacen("5 2 2 0 0", "5 2 2 0 1 4", 1);
        let (line, msg) = parse_err::<Dim2>(&p);
        assert_eq!(line, line_of(&t, "2 9"));
        assert!(msg.contains("node 9"), "{msg}");
    }

    #[test]
    fn unnamed_physical_groups_and_degenerate_elements() {
        let t = square_text();
        let m = parse_msh::<Dim2>(&t.replacen("2 3 \"rock\"", "2 33 \"other\"", 1), "t").unwrap();
        assert_eq!(m.groups().elements["physical_3"], vec![0, 1, 2, 3]);
        assert!(m.groups().elements["other"].is_empty());
        // Collapse element 8 onto a line: tags 2, 3 and a node on their edge.
        let deg = t.replacen("0.5 0.5 0", "1 0.5 0", 1);
        let (line, msg) = parse_err::<Dim2>(&deg);
        assert_eq!(line, line_of(&t, "8 2 3 6"));
        assert!(
            msg.contains("element 8") && msg.contains("degenerate"),
            "{msg}"
        );
    }

    #[test]
    fn every_truncation_is_handled() {
        for name in ["square.msh", "pyramid.msh"] {
            let t = std::fs::read_to_string(data(name)).unwrap();
            for cut in 0..t.len() {
                let r2 = parse_msh::<Dim2>(&t[..cut], "t");
                let r3 = parse_msh::<Dim3>(&t[..cut], "t");
                for e in [r2.err(), r3.err()].into_iter().flatten() {
                    assert!(
                        matches!(e, MeshError::Parse { line, .. } if line >= 1),
                        "{e}"
                    );
                }
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        #[test]
        fn truncations_never_panic(cut in 0usize..2000, three_d in any::<bool>()) {
            let t = if three_d {
                std::fs::read_to_string(data("pyramid.msh")).unwrap()
            } else {
                square_text()
            };
            let bytes = t.as_bytes();
            let s = String::from_utf8_lossy(&bytes[..cut.min(bytes.len())]);
            for e in [parse_msh::<Dim2>(&s, "t").err(), parse_msh::<Dim3>(&s, "t").err()].into_iter().flatten() {
                prop_assert!(matches!(e, MeshError::Parse { .. }), "{}", e);
            }
        }

        #[test]
        fn corruptions_never_panic(
            edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..6),
            three_d in any::<bool>(),
        ) {
            let t = if three_d {
                std::fs::read_to_string(data("pyramid.msh")).unwrap()
            } else {
                square_text()
            };
            let mut bytes = t.into_bytes();
            // Bias replacement bytes towards characters that matter to the parser.
            const ALPHABET: &[u8] = b"0123456789 \n-.e$\"x";
            for (i, b) in edits {
                let k = i.index(bytes.len());
                bytes[k] = if b < 200 { ALPHABET[b as usize % ALPHABET.len()] } else { b };
            }
            let s = String::from_utf8_lossy(&bytes);
            for e in [parse_msh::<Dim2>(&s, "t").err(), parse_msh::<Dim3>(&s, "t").err()].into_iter().flatten() {
                prop_assert!(matches!(e, MeshError::Parse { .. }), "{}", e);
            }
        }
    }
}
