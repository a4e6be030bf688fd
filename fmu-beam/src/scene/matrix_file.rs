//! A beam whose mass and stiffness come from 12 × 12 matrices in a text file, condensed from
//! another FE tool (3D paper §6): the file's format, its parser with errors that name file,
//! line and rule (the beam it gives: `from_scene::matrix_file_beam`).
//!
//! # Format
//! ```text
//! # comments start with '#', anywhere on a line; blank lines are ignored
//! length 0.2        # m, distance from node a (x = 0) to node b (x = length)
//! mass              # then 12 rows of 12 numbers: kg, kg m, kg m^2 by coordinate pair
//!   ...
//! stiffness         # then 12 rows of 12 numbers: N/m, N, N m by coordinate pair
//!   ...
//! ```
//! Coordinates, in this order: node a then node b, each [u, v, w, θx, θy, θz] in the beam
//! frame (x along the axis), translations in m, rotations in rad, right-handed
//! (θy = −dw/dx, θz = dv/dx for a beam): the element order of
//! `mechanics::beam::spatial_element`. The matrices are those of the free beam (no support removed).
//! `length`, `mass` and `stiffness` each appear exactly once, in any order; numbers are Rust
//! `f64` literals (`1e-3`, `-2.5E+4`) and must be finite.
//!
//! # What a refusal shows of the file
//! The file, the line and column, and what was expected there; of the text itself, only a
//! word of at most [`QUOTED`] characters of digits, letters, `.`, `+`, `-` and `_`, and only
//! where the file has shown itself a matrix file (a number of a block, the value after
//! `length`) or where it misspells a keyword; any other word is neither quoted nor measured.
//! A file that is not one (a scene naming `/etc/shadow` by mistake or by malice) is refused
//! with its first line and column and nothing of its content, not even a word's length.
//!
//! # Rules (each refusal names the file, the line and the rule)
//! - symmetric: |a_ij − a_ji| ≤ [`SYMMETRY_TOLERANCE`] · max |a| (relative to the largest
//!   entry: FE tools print to 6–16 digits, so a mismatch at that level is rounding);
//! - positive semi-definite: every eigenvalue (nalgebra's `SymmetricEigen` of the symmetric
//!   part) ≥ −[`EIGEN_TOLERANCE`] · the largest eigenvalue;
//! - the stiffness does not resist a rigid motion of the free beam (three translations, three
//!   small rotations about node a): |K φ| ≤ [`RIGID_TOLERANCE`] · max|K| · max|φ|, else the
//!   floating frame would see elastic forces from a rigid motion.

use nalgebra::DMatrix;
use std::path::Path;

/// Matrix size: 2 nodes × 6 coordinates.
pub const SIZE: usize = 12;
/// Relative tolerance of the symmetry rule (to the largest entry).
pub const SYMMETRY_TOLERANCE: f64 = 1e-9;
/// Relative tolerance of the semi-definiteness rule (to the largest eigenvalue).
pub const EIGEN_TOLERANCE: f64 = 1e-9;
/// Longest word of a file that a refusal quotes (characters).
pub const QUOTED: usize = 24;
/// Relative tolerance of the rigid-motion rule (to the largest entry times the mode's size).
pub const RIGID_TOLERANCE: f64 = 1e-9;

/// The two matrices and the length of a matrix file.
#[derive(Debug, Clone, PartialEq)]
pub struct MatrixFile {
    /// Distance between the two nodes (m).
    pub length: f64,
    /// The 12 × 12 nodal mass matrix of the free beam (kg, kg m, kg m^2 by coordinate pair).
    pub mass: DMatrix<f64>,
    /// The 12 × 12 nodal stiffness matrix of the free beam (N/m, N, N m by coordinate pair).
    pub stiffness: DMatrix<f64>,
}

/// Why a matrix file was refused. Row and column fields are 0-based; messages print them
/// 1-based, as a reader counts.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MatrixFileError {
    /// The file cannot be read.
    #[error("{file}: cannot read the matrix file: {message}")]
    Io {
        /// The file, as the caller named it.
        file: String,
        /// The system's error.
        message: String,
    },
    /// A line that breaks the format (an unknown keyword, a row of other than 12 numbers, a
    /// block or `length` given twice, …).
    #[error("{file}:{line}:{column}: {rule}")]
    Syntax {
        /// The file, as the caller named it.
        file: String,
        /// The offending line (1-based).
        line: usize,
        /// The column (1-based, in characters) of the offending word, 1 for a whole line.
        column: usize,
        /// What the format asks for there.
        rule: String,
    },
    /// The file ends with `length`, a block, or rows of a block missing.
    #[error("{file}: {rule}")]
    Incomplete {
        /// The file, as the caller named it.
        file: String,
        /// What is missing.
        rule: String,
    },
    #[error(
        "{file}:{line}: the {block} matrix must be symmetric: entry (row {r}, column {c}) = \
         {a:e} but (row {c}, column {r}) = {b:e}, apart by more than {tolerance:e} × the largest \
         entry {largest:e}",
        r = row + 1,
        c = col + 1
    )]
    /// A matrix is not symmetric to within [`SYMMETRY_TOLERANCE`] of its largest entry.
    NotSymmetric {
        /// The file, as the caller named it.
        file: String,
        /// The line of row `row` (1-based).
        line: usize,
        /// Which matrix: "mass" or "stiffness".
        block: &'static str,
        /// Row of the first asymmetric entry found (0-based; above the diagonal).
        row: usize,
        /// Its column (0-based).
        col: usize,
        /// Entry (row, col), in the matrix's unit for that coordinate pair.
        a: f64,
        /// Entry (col, row), its mirror.
        b: f64,
        /// The largest |entry| of the matrix.
        largest: f64,
        /// The relative tolerance, [`SYMMETRY_TOLERANCE`].
        tolerance: f64,
    },
    #[error(
        "{file}:{line}: the {block} matrix must be positive semi-definite: eigenvalue \
         {eigenvalue:e} is below −{tolerance:e} × the largest eigenvalue {largest:e}"
    )]
    /// A matrix has a negative eigenvalue beyond rounding: a mass or a stiffness that gives
    /// energy back.
    NotPositiveSemiDefinite {
        /// The file, as the caller named it.
        file: String,
        /// The line of the block's keyword (1-based).
        line: usize,
        /// Which matrix: "mass" or "stiffness".
        block: &'static str,
        /// The smallest eigenvalue of the matrix's symmetric part.
        eigenvalue: f64,
        /// The largest eigenvalue.
        largest: f64,
        /// The relative tolerance, [`EIGEN_TOLERANCE`].
        tolerance: f64,
    },
    #[error(
        "{file}:{line}: the stiffness matrix must not resist a rigid motion of the free beam: \
         the {motion} gives forces up to {force:e}, above {limit:e} ({tolerance:e} × largest \
         entry × mode size)"
    )]
    /// The stiffness gives forces for a rigid motion of the free beam.
    RigidMotionStrained {
        /// The file, as the caller named it.
        file: String,
        /// The line of the `stiffness` keyword (1-based).
        line: usize,
        /// Which rigid motion: "translation along x" … "rotation about z" (about node a).
        motion: &'static str,
        /// The largest nodal force or moment |(K φ)ᵢ| (N or N m) of the motion's mode φ (a
        /// translation of 1 m, or a rotation of 1 rad).
        force: f64,
        /// The force allowed: tolerance × the largest |entry| of K × the largest |φ|.
        limit: f64,
        /// The relative tolerance, [`RIGID_TOLERANCE`].
        tolerance: f64,
    },
}

/// A word of the file as a message may show it: quoted if short and made of the characters of
/// numbers and keywords, else not at all (not even its length: issue 45).
fn shown(word: &str) -> String {
    let plain = word
        .chars()
        .all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '+' | '-' | '_'));
    if plain && word.chars().count() <= QUOTED {
        format!("`{word}`")
    } else {
        "a word (not shown)".to_string()
    }
}

/// Edit distance of two short words (insertions, deletions, substitutions).
fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let here = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb))
                .min(row[j] + 1)
                .min(here + 1);
            prev = here;
        }
    }
    row[b.len()]
}

/// Column (1-based, in characters) where `word`, a slice of `line`, starts.
fn column_of(line: &str, word: &str) -> usize {
    let at = (word.as_ptr() as usize).saturating_sub(line.as_ptr() as usize);
    line.get(..at).map_or(0, |s| s.chars().count()) + 1
}

/// A block being read: name, header line, rows with their line numbers.
struct Block {
    name: &'static str,
    header: usize,
    rows: Vec<(usize, Vec<f64>)>,
}

/// Parses and checks the text of a matrix file; `file` names it in errors.
pub fn parse(text: &str, file: &str) -> Result<MatrixFile, MatrixFileError> {
    let syntax = |line: usize, column: usize, rule: String| MatrixFileError::Syntax {
        file: file.to_string(),
        line,
        column,
        rule,
    };
    let mut length: Option<(usize, f64)> = None;
    let mut done: Vec<Block> = Vec::new();
    let mut open: Option<Block> = None;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let mut words = content.split_whitespace();
        let first = words.next().unwrap_or("");
        let keyword = match first {
            "mass" => Some("mass"),
            "stiffness" => Some("stiffness"),
            "length" => Some("length"),
            _ => None,
        };
        if let Some(block) = open.as_mut() {
            if keyword.is_some() {
                return Err(syntax(
                    line,
                    column_of(raw, first),
                    format!(
                        "the {} block (line {}) has {} rows before `{first}`; it needs 12 rows \
                         of 12 numbers",
                        block.name,
                        block.header,
                        block.rows.len()
                    ),
                ));
            }
            let mut row = Vec::with_capacity(SIZE);
            for token in content.split_whitespace() {
                let x: f64 = token.parse().map_err(|_| {
                    syntax(
                        line,
                        column_of(raw, token),
                        format!(
                            "{} in the {} block is not a number",
                            shown(token),
                            block.name
                        ),
                    )
                })?;
                if !x.is_finite() {
                    return Err(syntax(
                        line,
                        column_of(raw, token),
                        format!("{} in the {} block is not finite", shown(token), block.name),
                    ));
                }
                row.push(x);
            }
            if row.len() != SIZE {
                return Err(syntax(
                    line,
                    column_of(raw, content),
                    format!(
                        "row {} of the {} block needs 12 numbers, found {}",
                        block.rows.len() + 1,
                        block.name,
                        row.len()
                    ),
                ));
            }
            block.rows.push((line, row));
            if block.rows.len() == SIZE {
                done.extend(open.take());
            }
            continue;
        }
        match keyword {
            Some("length") => {
                if let Some((first_line, _)) = length {
                    return Err(syntax(
                        line,
                        column_of(raw, first),
                        format!("`length` given more than once (first on line {first_line})"),
                    ));
                }
                let value = words.next();
                let x = value.and_then(|v| v.parse::<f64>().ok());
                match (x, words.next()) {
                    (Some(x), None) if x.is_finite() && x > 0.0 => length = Some((line, x)),
                    _ => {
                        let rest = content.get("length".len()..).unwrap_or("").trim();
                        let found = match rest.split_whitespace().count() {
                            0 => "nothing".to_string(),
                            1 => shown(rest),
                            n => format!("{n} words"),
                        };
                        return Err(syntax(
                            line,
                            column_of(raw, first),
                            format!("`length` needs one positive finite number (m), found {found}"),
                        ));
                    }
                }
            }
            Some(name) => {
                if let Some(prev) = done.iter().find(|b| b.name == name) {
                    return Err(syntax(
                        line,
                        column_of(raw, first),
                        format!(
                            "the {name} block is given more than once (first on line {})",
                            prev.header
                        ),
                    ));
                }
                if words.next().is_some() {
                    return Err(syntax(
                        line,
                        column_of(raw, first),
                        format!("`{name}` stands alone on its line; its 12 rows follow"),
                    ));
                }
                open = Some(Block {
                    name,
                    header: line,
                    rows: Vec::new(),
                });
            }
            None => {
                // a misspelt keyword is named; anything else only measured
                let near = ["length", "mass", "stiffness"]
                    .iter()
                    .any(|k| first.len() <= 12 && distance(first, k) <= 2);
                let found = if near {
                    shown(first)
                } else {
                    "(not shown)".to_string()
                };
                return Err(syntax(
                    line,
                    column_of(raw, first),
                    format!("unknown keyword {found}: expected `length`, `mass` or `stiffness`"),
                ));
            }
        }
    }
    let incomplete = |rule: String| MatrixFileError::Incomplete {
        file: file.to_string(),
        rule,
    };
    if let Some(block) = open {
        return Err(incomplete(format!(
            "the {} block (line {}) ends after {} rows; it needs 12 rows of 12 numbers",
            block.name,
            block.header,
            block.rows.len()
        )));
    }
    let Some((_, length)) = length else {
        return Err(incomplete("`length` is missing".into()));
    };
    let take = |name: &str| {
        done.iter()
            .find(|b| b.name == name)
            .ok_or_else(|| incomplete(format!("the {name} block is missing")))
    };
    let (mb, kb) = (take("mass")?, take("stiffness")?);
    for b in [mb, kb] {
        check_symmetric_psd(b, file)?;
    }
    let to_matrix = |b: &Block| DMatrix::from_fn(SIZE, SIZE, |i, j| b.rows[i].1[j]);
    let out = MatrixFile {
        length,
        mass: to_matrix(mb),
        stiffness: to_matrix(kb),
    };
    check_rigid_motion(&out.stiffness, length, kb.header, file)?;
    Ok(out)
}

fn check_symmetric_psd(b: &Block, file: &str) -> Result<(), MatrixFileError> {
    let m = DMatrix::from_fn(SIZE, SIZE, |i, j| b.rows[i].1[j]);
    let largest = m.amax();
    for i in 0..SIZE {
        for j in i + 1..SIZE {
            if (m[(i, j)] - m[(j, i)]).abs() > SYMMETRY_TOLERANCE * largest {
                return Err(MatrixFileError::NotSymmetric {
                    file: file.to_string(),
                    line: b.rows[i].0,
                    block: b.name,
                    row: i,
                    col: j,
                    a: m[(i, j)],
                    b: m[(j, i)],
                    largest,
                    tolerance: SYMMETRY_TOLERANCE,
                });
            }
        }
    }
    let sym = (&m + m.transpose()) * 0.5;
    let eig = sym.symmetric_eigen().eigenvalues;
    let (min, max) = (eig.min(), eig.max());
    if min < -EIGEN_TOLERANCE * max.max(0.0) || max <= 0.0 && min < 0.0 {
        return Err(MatrixFileError::NotPositiveSemiDefinite {
            file: file.to_string(),
            line: b.header,
            block: b.name,
            eigenvalue: min,
            largest: max,
            tolerance: EIGEN_TOLERANCE,
        });
    }
    Ok(())
}

/// Nodal rigid modes of a free two-node beam: translations along x, y, z and small rotations
/// about x, y, z through node a.
fn rigid_modes(length: f64) -> [(&'static str, [f64; SIZE]); 6] {
    let mut modes = [
        ("translation along x", [0.0; SIZE]),
        ("translation along y", [0.0; SIZE]),
        ("translation along z", [0.0; SIZE]),
        ("rotation about x", [0.0; SIZE]),
        ("rotation about y", [0.0; SIZE]),
        ("rotation about z", [0.0; SIZE]),
    ];
    for node in 0..2 {
        let o = 6 * node;
        let x = length * node as f64;
        for k in 0..6 {
            modes[k].1[o + k] = 1.0;
        }
        modes[4].1[o + 2] = -x; // w = −x θy
        modes[5].1[o + 1] = x; // v = x θz
    }
    modes
}

fn check_rigid_motion(
    k: &DMatrix<f64>,
    length: f64,
    line: usize,
    file: &str,
) -> Result<(), MatrixFileError> {
    for (motion, phi) in rigid_modes(length) {
        let size = phi.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let limit = RIGID_TOLERANCE * k.amax() * size;
        let force = (0..SIZE)
            .map(|i| (0..SIZE).map(|j| k[(i, j)] * phi[j]).sum::<f64>().abs())
            .fold(0.0, f64::max);
        if force > limit {
            return Err(MatrixFileError::RigidMotionStrained {
                file: file.to_string(),
                line,
                motion,
                force,
                limit,
                tolerance: RIGID_TOLERANCE,
            });
        }
    }
    Ok(())
}

impl MatrixFile {
    /// Reads and checks a matrix file: a regular file of at most
    /// [`super::files::MAX_MATRIX_FILE_BYTES`].
    pub fn load(path: &Path) -> Result<MatrixFile, MatrixFileError> {
        let file = path.display().to_string();
        let text =
            super::files::read_capped(path, super::files::MAX_MATRIX_FILE_BYTES).map_err(|e| {
                MatrixFileError::Io {
                    file: file.clone(),
                    message: e.to_string(),
                }
            })?;
        parse(&text, &file)
    }

    /// The file's text (numbers round-trip exactly), with a first comment line.
    pub fn to_text(&self, comment: &str) -> String {
        let mut s = format!(
            "# {comment}\n# coordinates per node: u v w θx θy θz (m, rad); node a at x = 0, \
             node b at x = length\nlength {}\n",
            self.length
        );
        for (name, m, units) in [
            ("mass", &self.mass, "kg, kg m, kg m^2"),
            ("stiffness", &self.stiffness, "N/m, N, N m"),
        ] {
            s.push_str(&format!("{name}  # {units}\n"));
            for i in 0..SIZE {
                let row: Vec<String> = (0..SIZE).map(|j| format!("{:e}", m[(i, j)])).collect();
                s.push_str(&row.join(" "));
                s.push('\n');
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 45: a file that is not a matrix file (/proc/self/environ, a secrets file named by
    /// mistake or by malice) was refused with the length of its first word; a word inside a
    /// block that is not shown had its length told too. Now neither says anything of the word.
    #[test]
    fn a_word_not_shown_is_not_measured_either() {
        for text in [
            "PATH=/usr/local/sbin:/usr/bin\0HOME=/root\0",
            "root:$y$j9T$SECRETSECRETSECRET:19000:0:99999:7:::\n",
            "token 0123456789abcdef\n",
        ] {
            let m = parse(text, "f.txt").unwrap_err().to_string();
            assert!(!m.contains("characters") && !m.contains("SECRET"), "{m}");
            for w in text.split(|c: char| !c.is_ascii_alphanumeric()) {
                assert!(w.len() < 4 || !m.contains(w), "{w} in {m}");
            }
        }
        let block = format!(
            "length 1\nmass\n{} 1 1 1 1 1 1 1 1 1 1 1\n",
            "x=".repeat(30)
        );
        let m = parse(&block, "f.txt").unwrap_err().to_string();
        assert!(!m.contains("60") && !m.contains("characters"), "{m}");
    }
}
