//! A small `--flag value` parser: the CLI needs no more.

use std::collections::HashMap;

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
}
