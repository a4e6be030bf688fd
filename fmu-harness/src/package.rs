//! `fmu-harness package`: a scene file → an FMI 2.0 co-simulation FMU.
//!
//! Layout of the FMU: `modelDescription.xml`, one engine library per platform under the
//! scene's name (`binaries/linux64/<modelIdentifier>.so`, `binaries/win64/<modelIdentifier>.dll`),
//! `resources/scene.toml` (the canonical scene text the engine reads in fmi2Instantiate),
//! `resources/guid.txt` (checked there against fmuGUID) and `documentation/index.html`.

use crate::archive::{self, Entry};
use crate::engine_library;
use crate::error::HarnessError;
use crate::guid::guid;
use crate::model_description;
use crate::platform::{FmiVersion, Platform};
use fmu_beam::Scene;
use fmu_beam::VariableTable;
use std::path::{Path, PathBuf};

/// File name of the engine cdylib that cargo builds for Linux.
pub const ENGINE_LIBRARY: &str = "libfmu_beam.so";

/// One `--binary` of `fmu-harness package`: `[PLATFORM=]PATH`, the platform named or (None)
/// read from the library's header.
#[derive(Debug, Clone, PartialEq)]
pub struct BinaryArg {
    pub platform: Option<Platform>,
    pub path: PathBuf,
}

impl std::str::FromStr for BinaryArg {
    type Err = String;

    /// `linux64=target/release/libfmu_beam.so`, `win64=fmu_beam.dll` or a bare path. A prefix
    /// that looks like a platform folder but is none the packager knows is refused.
    fn from_str(text: &str) -> Result<BinaryArg, String> {
        if let Some((head, path)) = text.split_once('=') {
            if let Some(platform) = Platform::from_folder(head) {
                return Ok(BinaryArg {
                    platform: Some(platform),
                    path: PathBuf::from(path),
                });
            }
            if !head.is_empty() && head.chars().all(|c| c.is_ascii_alphanumeric()) {
                let known: Vec<&str> = Platform::ALL.iter().map(|p| p.folder()).collect();
                return Err(format!(
                    "unknown platform '{head}' (the packager fills {})",
                    known.join(", ")
                ));
            }
        }
        Ok(BinaryArg {
            platform: None,
            path: PathBuf::from(text),
        })
    }
}

/// What a packaging run produced.
#[derive(Debug, Clone, PartialEq)]
pub struct Packaged {
    pub output: PathBuf,
    pub model_identifier: String,
    pub guid: String,
    pub variables: usize,
    /// The engine library packaged for each platform, in [`Platform::ALL`] order.
    pub binaries: Vec<(Platform, PathBuf)>,
}

/// The files of an FMU, before zipping.
#[derive(Debug, Clone, PartialEq)]
pub struct FmuContents {
    pub model_identifier: String,
    pub guid: String,
    pub model_description: String,
    pub scene_text: String,
    /// documentation/index.html: the variables (from the same table as the XML), the resolved
    /// effects and why (`fmu-harness explain`), the direct feedthrough.
    pub documentation: String,
    pub variables: usize,
}

/// modelDescription.xml, scene text and GUID of a scene packaged with the given engine
/// binaries. The GUID digests the unsigned XML, the scene text and, for each platform in order,
/// its folder name, the binary's length (u64 little-endian) and bytes: any change of any binary
/// changes it, and so does moving bytes from one binary to another.
pub fn contents(
    scene: &Scene,
    binaries: &[(Platform, &[u8])],
) -> Result<FmuContents, HarnessError> {
    contents_with(scene, binaries, FmiVersion::V2)
}

/// [`contents`] of an FMU of `version`: FMI 3.0's model description
/// ([`model_description::fmi3::render`], its instantiationToken the GUID) and platform folders
/// in the GUID's input; the same scene text and documentation.
pub fn contents_with(
    scene: &Scene,
    binaries: &[(Platform, &[u8])],
    version: FmiVersion,
) -> Result<FmuContents, HarnessError> {
    let table = VariableTable::build(scene);
    let scene_text = canonical_text(scene)?;
    let render = match version {
        FmiVersion::V2 => model_description::render,
        FmiVersion::V3 => model_description::fmi3::render,
    };
    let unsigned = render(scene, &table, "")?;
    let lengths: Vec<[u8; 8]> = binaries
        .iter()
        .map(|(_, b)| (b.len() as u64).to_le_bytes())
        .collect();
    let mut parts: Vec<&[u8]> = vec![unsigned.as_bytes(), scene_text.as_bytes()];
    for ((platform, bytes), length) in binaries.iter().zip(&lengths) {
        parts.extend([platform.folder_in(version).as_bytes(), &length[..], bytes]);
    }
    let guid = guid(&parts);
    let model_description = render(scene, &table, &guid)?;
    Ok(FmuContents {
        model_identifier: scene.name.clone(),
        guid,
        model_description,
        scene_text,
        documentation: documentation(scene, &table)?,
        variables: table.variables.len(),
    })
}

/// documentation/index.html: the scene's description, its variables (the table that
/// modelDescription.xml is written from: name, causality, variability, type, unit, start,
/// meaning; inputs first, then outputs, then parameters), its resolved effects and its direct
/// feedthrough (`fmu_beam::explain_feedthrough`); first, the accuracy the scene was tuned for
/// (`fmu_beam::explain_accuracy`), refused if its output is not one of the unit's.
fn documentation(scene: &Scene, table: &VariableTable) -> Result<String, HarnessError> {
    let effects = fmu_beam::resolve_effects(scene).explain(scene);
    let feedthrough = fmu_beam::explain_feedthrough(scene, table);
    let accuracy = match accuracy_statement(scene, table)? {
        text if text.is_empty() => String::new(),
        text => format!("<p>{}</p>\n", escape(&text)),
    };
    Ok(format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{name}</title>\n{STYLE}</head>\n\
         <body>\n<h1>{name}</h1>\n<p>{description}</p>\n{accuracy}<h2>Variables</h2>\n{variables}\
         <h2>Effects</h2>\n<pre>\n{effects}</pre>\n\
         <h2>Direct feedthrough and directional derivatives</h2>\n<pre>\n{feedthrough}</pre>\n\
         </body></html>\n",
        name = escape(&scene.name),
        description = escape(&scene.description),
        variables = variables_html(table),
        effects = escape(&effects),
        feedthrough = escape(&feedthrough),
    ))
}

/// The scene's `[accuracy]` statement (empty without one); refused where its output is not a
/// Real output of the unit.
fn accuracy_statement(scene: &Scene, table: &VariableTable) -> Result<String, HarnessError> {
    fmu_beam::explain_accuracy(scene, table).map_err(|message| HarnessError::AccuracyStatement {
        scene: scene.name.clone(),
        message,
    })
}

/// What `explain` prints (the command and the Python package's `Scene.explain()`): the
/// accuracy the scene was tuned for, then its effects, why, and their share of the cost.
pub fn explain(scene: &Scene) -> Result<String, HarnessError> {
    let accuracy = accuracy_statement(scene, &VariableTable::build(scene))?;
    let effects = fmu_beam::resolve_effects(scene).explain(scene);
    Ok(if accuracy.is_empty() {
        effects
    } else {
        format!("{accuracy}\n{effects}")
    })
}

const STYLE: &str = "<style>table{border-collapse:collapse}td,th{border:1px solid #ccc;\
                     padding:2px 6px;text-align:left}td.num{text-align:right}</style>";

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The variables as an HTML table, one row per variable: what a master's user connects
/// (inputs, outputs) first, then what they may set (parameters).
fn variables_html(table: &VariableTable) -> String {
    use fmu_beam::Causality;
    let mut html = String::from(
        "<p>Units are SI. An input is held over a communication step (or extrapolated from the \
         derivatives a master sets); a tunable parameter may be set between steps, a fixed one \
         only before initialization.</p>\n<table id=\"variables\">\n<tr><th>name</th>\
         <th>causality</th><th>variability</th><th>type</th><th>unit</th><th>start</th>\
         <th>valueReference</th><th>meaning</th></tr>\n",
    );
    let rank = |c: Causality| match c {
        Causality::Input => 0,
        Causality::Output => 1,
        Causality::Parameter | Causality::CalculatedParameter => 2,
    };
    let mut rows: Vec<_> = table.variables.iter().collect();
    rows.sort_by_key(|v| (rank(v.causality), v.vr));
    for v in rows {
        html.push_str(&format!(
            "<tr><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td><td>{}</td></tr>\n",
            escape(&v.name),
            v.causality.as_str(),
            v.variability.as_str(),
            v.ty.as_str(),
            escape(model_description::unit(v).unwrap_or("")),
            model_description::start_text(v).unwrap_or_default(),
            v.vr,
            escape(&v.description),
        ));
    }
    html.push_str("</table>\n");
    html
}

/// The scene text the engine will read, checked to read back as the same scene.
fn canonical_text(scene: &Scene) -> Result<String, HarnessError> {
    let text = scene.to_toml_string();
    let refuse = |message: String| HarnessError::CanonicalScene {
        scene: scene.name.clone(),
        message,
    };
    match Scene::from_toml_str(&text, "resources/scene.toml") {
        Ok(back) if back == *scene && !text.is_empty() => Ok(text),
        Ok(_) => Err(refuse("it reads back as a different scene".into())),
        Err(e) => Err(refuse(e.to_string())),
    }
}

/// Loads the scene, builds the FMU with one engine library per platform (without `binaries`,
/// the Linux engine of [`default_binary`]) and writes it to `output` (atomically). Each
/// library's platform is read from its header; one named in `binaries` must agree with it, and
/// a platform may come only once. A library is read only if it is a regular file of at most
/// [`engine_library::MAX_LIBRARY_BYTES`], and kept only if it exports every FMI 2.0
/// co-simulation function ([`engine_library::check_exports`]).
pub fn package(
    scene_path: &Path,
    output: &Path,
    binaries: &[BinaryArg],
) -> Result<Packaged, HarnessError> {
    package_scene(&Scene::load(scene_path)?, output, binaries)
}

/// [`package`] as an FMU of `version` (`--fmi-version`).
pub fn package_as(
    scene_path: &Path,
    output: &Path,
    binaries: &[BinaryArg],
    version: FmiVersion,
) -> Result<Packaged, HarnessError> {
    package_scene_as(&Scene::load(scene_path)?, output, binaries, version)
}

/// [`package`] of a scene already loaded and validated (the Python package's `Scene.package`).
pub fn package_scene(
    scene: &Scene,
    output: &Path,
    binaries: &[BinaryArg],
) -> Result<Packaged, HarnessError> {
    package_scene_as(scene, output, binaries, FmiVersion::V2)
}

/// [`package_scene`] as an FMU of `version`: FMI 2.0 or 3.0 from the same engine libraries
/// (each exports both standards' functions, checked for the one packaged).
pub fn package_scene_as(
    scene: &Scene,
    output: &Path,
    binaries: &[BinaryArg],
    version: FmiVersion,
) -> Result<Packaged, HarnessError> {
    // an output that would be refused is refused before the work
    crate::output_file::check(output)?;
    let given = if binaries.is_empty() {
        vec![BinaryArg {
            platform: None,
            path: default_binary()?,
        }]
    } else {
        binaries.to_vec()
    };
    let mut libraries: Vec<(Platform, PathBuf, Vec<u8>)> = Vec::new();
    for arg in given {
        let bytes = engine_library::read(&arg.path)?;
        let found = Platform::of_library(&bytes);
        let platform = match (arg.platform, found) {
            (Some(named), Some(found)) if named == found => found,
            (None, Some(found)) => found,
            (named, found) => {
                return Err(HarnessError::BinaryPlatform {
                    path: arg.path,
                    named,
                    found,
                })
            }
        };
        engine_library::check_exports_of(&arg.path, &bytes, platform, version)?;
        if let Some((_, first, _)) = libraries.iter().find(|(p, _, _)| *p == platform) {
            return Err(HarnessError::DuplicatePlatform {
                platform,
                first: first.clone(),
                second: arg.path,
            });
        }
        libraries.push((platform, arg.path, bytes));
    }
    libraries.sort_by_key(|(p, _, _)| *p);
    let parts: Vec<(Platform, &[u8])> = libraries
        .iter()
        .map(|(p, _, b)| (*p, b.as_slice()))
        .collect();
    let c = contents_with(scene, &parts, version)?;
    let paths: Vec<String> = libraries
        .iter()
        .map(|(p, _, _)| {
            format!(
                "binaries/{}/{}.{}",
                p.folder_in(version),
                c.model_identifier,
                p.extension()
            )
        })
        .collect();
    let mut entries = vec![Entry {
        path: "modelDescription.xml",
        data: c.model_description.as_bytes(),
        mode: 0o644,
    }];
    for (path, (_, _, bytes)) in paths.iter().zip(&libraries) {
        entries.push(Entry {
            path,
            data: bytes,
            mode: 0o755,
        });
    }
    entries.extend([
        Entry {
            path: "resources/scene.toml",
            data: c.scene_text.as_bytes(),
            mode: 0o644,
        },
        Entry {
            path: "resources/guid.txt",
            data: c.guid.as_bytes(),
            mode: 0o644,
        },
        Entry {
            path: "documentation/index.html",
            data: c.documentation.as_bytes(),
            mode: 0o644,
        },
    ]);
    archive::write_fmu(output, &entries)?;
    Ok(Packaged {
        output: output.to_path_buf(),
        model_identifier: c.model_identifier,
        guid: c.guid,
        variables: c.variables,
        binaries: libraries
            .into_iter()
            .map(|(p, path, _)| (p, path))
            .collect(),
    })
}

/// The engine cdylib of the harness's target directory: `target/release/`, else beside this
/// executable (`target/<profile>/`).
pub fn default_binary() -> Result<PathBuf, HarnessError> {
    let exe = std::env::current_exe()
        .map_err(|e| HarnessError::io("fmu-harness", "locating the executable", e))?;
    let candidates = binary_candidates(&exe);
    candidates
        .iter()
        .find(|p| p.is_file())
        .cloned()
        .ok_or(HarnessError::BinaryNotFound {
            searched: candidates,
        })
}

/// Where to look for the engine library, in order, given the harness executable's path.
pub fn binary_candidates(exe: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let Some(mut dir) = exe.parent() else {
        return out;
    };
    // test executables live in target/<profile>/deps
    if dir.file_name().is_some_and(|n| n == "deps") {
        if let Some(p) = dir.parent() {
            dir = p;
        }
    }
    if let Some(target) = dir.parent() {
        out.push(target.join("release").join(ENGINE_LIBRARY));
    }
    let beside = dir.join(ENGINE_LIBRARY);
    if !out.contains(&beside) {
        out.push(beside);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{binary_candidates, BinaryArg};
    use crate::platform::{FmiVersion, Platform};
    use std::path::{Path, PathBuf};

    #[test]
    fn binary_arguments_name_a_platform_or_only_a_path() {
        let arg = |s: &str| s.parse::<BinaryArg>();
        let named = |p, path: &str| BinaryArg {
            platform: Some(p),
            path: PathBuf::from(path),
        };
        assert_eq!(
            arg("win64=target/a=b.dll"),
            Ok(named(Platform::Win64, "target/a=b.dll"))
        );
        assert_eq!(
            arg("linux64=lib.so"),
            Ok(named(Platform::Linux64, "lib.so"))
        );
        assert_eq!(
            arg("target/release/libfmu_beam.so"),
            Ok(BinaryArg {
                platform: None,
                path: PathBuf::from("target/release/libfmu_beam.so")
            })
        );
        assert_eq!(arg("./a=b.so").unwrap().path, PathBuf::from("./a=b.so"));
        assert!(arg("darwin64=x.dylib")
            .unwrap_err()
            .contains("unknown platform 'darwin64'"));
    }

    /// `--fmi-version`: 2 by default, 3 with FMI 3.0's platform tuples; the `--binary`
    /// prefixes of either version name the same platforms.
    #[test]
    fn fmi_versions_and_their_platform_folders() {
        assert_eq!(FmiVersion::default(), FmiVersion::V2);
        assert_eq!("3".parse(), Ok(FmiVersion::V3));
        assert_eq!("2.0".parse(), Ok(FmiVersion::V2));
        assert!("4".parse::<FmiVersion>().is_err());
        let v3: Vec<&str> = Platform::ALL
            .iter()
            .map(|p| p.folder_in(FmiVersion::V3))
            .collect();
        assert_eq!(v3, ["x86_64-linux", "x86_64-windows"]);
        assert_eq!(
            "x86_64-windows=a.dll"
                .parse::<BinaryArg>()
                .unwrap()
                .platform,
            Some(Platform::Win64)
        );
    }

    #[test]
    fn engine_library_is_looked_for_in_release_then_beside_the_executable() {
        assert_eq!(
            binary_candidates(Path::new("/r/target/debug/fmu-harness")),
            vec![
                PathBuf::from("/r/target/release/libfmu_beam.so"),
                PathBuf::from("/r/target/debug/libfmu_beam.so")
            ]
        );
        assert_eq!(
            binary_candidates(Path::new("/r/target/release/deps/x-123")),
            vec![PathBuf::from("/r/target/release/libfmu_beam.so")]
        );
    }
}
