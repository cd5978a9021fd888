//! A small `--flag value` parser: the CLI needs no more. Also the mesh loading that `--strict`
//! and `--prim-map` shape, shared by the commands that take `--scene`.

use raytrail::conformance::NamedScene;
use raytrail::core::mesh::{write_sources_csv, LoadOptions, LoadReport};
use std::collections::HashMap;

/// The switch that makes mesh loading strict (`run`, `trace`, `rays`, `bench`): an element that is
/// not a triangle or polygon (a face of fewer than three vertices, an OBJ line or point, a glTF
/// line or point primitive) fails the load instead of being skipped with a warning.
pub const STRICT: &str = "strict";

/// Flags given as `--name value` or bare `--name`.
pub struct Args {
    values: HashMap<String, Option<String>>,
}

impl Args {
    /// Parses `args`; `switches` are the flags that take no value.
    pub fn parse(args: &[String], switches: &[&str]) -> Result<Args, String> {
        let mut values = HashMap::new();
        let mut it = args.iter();
        while let Some(a) = it.next() {
            let name =
                a.strip_prefix("--").ok_or_else(|| format!("unexpected argument '{a}' (flags start with --)"))?;
            if switches.contains(&name) {
                values.insert(name.to_string(), None);
            } else {
                let v = it.next().ok_or_else(|| format!("--{name} needs a value"))?;
                values.insert(name.to_string(), Some(v.clone()));
            }
        }
        Ok(Args { values })
    }

    /// Rejects flags outside `known`.
    pub fn only(&self, known: &[&str]) -> Result<(), String> {
        match self.values.keys().find(|k| !known.contains(&k.as_str())) {
            Some(k) => Err(format!(
                "unknown flag --{k}; known: {}",
                known.iter().map(|k| format!("--{k}")).collect::<Vec<_>>().join(" ")
            )),
            None => Ok(()),
        }
    }

    /// The value of `--name`, if given.
    pub fn get(&self, name: &str) -> Option<&str> {
        self.values.get(name).and_then(|v| v.as_deref())
    }

    /// Whether the switch `--name` was given.
    pub fn has(&self, name: &str) -> bool {
        self.values.contains_key(name)
    }

    /// The value of `--name` parsed, or `default`.
    pub fn num<T: std::str::FromStr>(&self, name: &str, default: T) -> Result<T, String> {
        match self.get(name) {
            None => Ok(default),
            Some(v) => v.parse().map_err(|_| format!("--{name}: '{v}' is not a valid number")),
        }
    }

    /// The value of `--name`, required.
    pub fn required(&self, name: &str) -> Result<&str, String> {
        self.get(name).ok_or_else(|| format!("--{name} is required"))
    }

    /// The mesh loading policy of [`STRICT`].
    pub fn load_options(&self) -> LoadOptions {
        LoadOptions { strict: self.has(STRICT), ..LoadOptions::default() }
    }
}

/// Loads a scene (a mesh file or `builtin`) with `options`; returns the warning line to print
/// when loading skipped elements (print it with [`warn`] once any progress line is done).
pub fn load_scene(path: &str, options: &LoadOptions) -> Result<(NamedScene, LoadReport, Option<String>), String> {
    let (named, report) = raytrail::load_scene_with(path, options)?;
    let warning = skipped_warning(path, &report);
    Ok((named, report, warning))
}

/// The one warning line for what loading `path` skipped, if it skipped anything.
pub fn skipped_warning(path: &str, report: &LoadReport) -> Option<String> {
    report.summary(path).map(|s| format!("warning: {s} (--{STRICT} makes this an error)"))
}

/// Prints a warning line, if there is one, on standard error.
pub fn warn(warning: &Option<String>) {
    if let Some(w) = warning {
        eprintln!("{w}");
    }
}

/// Writes the primitive-id map (`--prim-map`): CSV `prim,file,<where>`, one row per triangle.
pub fn write_prim_map(out: &str, scene: &str, report: &LoadReport) -> Result<(), String> {
    let fail = |e: std::io::Error| format!("cannot write {out}: {e}");
    let file = std::fs::File::create(out).map_err(fail)?;
    let mut w = std::io::BufWriter::new(file);
    write_sources_csv(&mut w, scene, &report.sources).map_err(fail)?;
    std::io::Write::flush(&mut w).map_err(fail)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(s: &str) -> Args {
        Args::parse(&s.split_whitespace().map(str::to_string).collect::<Vec<_>>(), &[STRICT]).unwrap()
    }

    /// A file in a scratch folder of this process.
    fn scratch(name: &str, data: &[u8]) -> String {
        let dir = std::env::temp_dir().join(format!("raytrail-cli-args-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, data).unwrap();
        path.display().to_string()
    }

    const OBJ: &[u8] = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nl 1 2 3\np 1\nf 1 2 3\n";

    #[test]
    fn strict_switch() {
        assert!(!args("--scene a.obj").load_options().strict);
        assert!(args("--scene a.obj --strict").load_options().strict);
        assert!(!args("--strict").load_options().sources);
    }

    #[test]
    fn lenient_load_warns_once_and_strict_fails() {
        let path = scratch("edges.obj", OBJ);
        let (named, report, warning) = load_scene(&path, &args("").load_options()).unwrap();
        assert_eq!(named.scene.triangles().len(), 1);
        assert_eq!(report.skipped, 3);
        assert_eq!(
            warning.unwrap(),
            format!(
                "warning: {path}: skipped 3 elements that are not triangles or polygons, the first at line 4: \
                 a face with 2 vertices (--strict makes this an error)"
            )
        );
        let e = load_scene(&path, &args("--strict").load_options()).unwrap_err();
        assert_eq!(e, format!("{path}:4: face has 2 vertices; a face needs at least 3"));
        // Nothing skipped: no warning.
        let clean = scratch("clean.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        assert_eq!(load_scene(&clean, &LoadOptions::default()).unwrap().2, None);
    }

    #[test]
    fn prim_map_file() {
        let path = scratch("map.obj", OBJ);
        let options = LoadOptions { sources: true, ..LoadOptions::default() };
        let (_, report, _) = load_scene(&path, &options).unwrap();
        let out = scratch("map.csv", b"");
        write_prim_map(&out, &path, &report).unwrap();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), format!("prim,file,line\n0,{path},7\n"));
        let e = write_prim_map("/nonexistent/dir/map.csv", &path, &report).unwrap_err();
        assert!(e.starts_with("cannot write /nonexistent/dir/map.csv: "), "{e}");
    }
}
