//! Reading a scene file: TOML with `--set` overrides, and errors that
//! name the file and the line or the field.

use crate::Error;
use std::path::Path;

/// Apply `key.path=value` to a TOML tree; the value is read as TOML
/// (number, boolean, string, array) or else taken as a string.
pub fn apply_set(root: &mut toml::Table, assignment: &str) -> Result<(), Error> {
    let bad = |m: String| Error::Scene(format!("--set {assignment}: {m}"));
    let (path, value) = assignment
        .split_once('=')
        .ok_or_else(|| bad("expected key=value".into()))?;
    let keys: Vec<&str> = path.trim().split('.').collect();
    if keys.iter().any(|k| k.is_empty()) {
        return Err(bad("empty key".into()));
    }
    let parsed: toml::Value = toml::from_str::<toml::Table>(&format!("v = {}", value.trim()))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(value.trim().to_string()));
    let mut table = root;
    for k in &keys[..keys.len() - 1] {
        table = table
            .entry(k.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()))
            .as_table_mut()
            .ok_or_else(|| bad(format!("{k} is not a table")))?;
    }
    table.insert(keys[keys.len() - 1].to_string(), parsed);
    Ok(())
}

/// Where a bad value sits when serde can only name its table (`ve` is an
/// internally tagged enum, whose fields serde reads from a buffer): the
/// line in that table holding the value the message quotes, and its key.
fn locate(text: &str, table: &str, message: &str) -> Option<(usize, String)> {
    let quoted = message.split('"').nth(1)?;
    let header = format!("[{table}]");
    let start = text.lines().position(|l| l.trim() == header)?;
    text.lines()
        .enumerate()
        .skip(start + 1)
        .take_while(|(_, l)| !l.trim_start().starts_with('['))
        .find(|(_, l)| l.contains(&format!("\"{quoted}\"")))
        .and_then(|(i, l)| Some((i + 1, format!("{table}.{}", l.split('=').next()?.trim()))))
}

/// A scene file's text; the error names the file.
pub fn read(path: &Path) -> Result<String, Error> {
    std::fs::read_to_string(path)
        .map_err(|e| Error::Scene(format!("{}: cannot read: {e}", path.display())))
}

/// `scene` if `check` passes it; the error names `source`.
pub fn checked<T>(
    scene: T,
    source: &str,
    check: impl FnOnce(&T) -> Result<(), Error>,
) -> Result<T, Error> {
    check(&scene).map_err(|m| Error::Scene(format!("{source}: {m}")))?;
    Ok(scene)
}

/// Parse TOML scene text into `T`, applying `--set` overrides; an error
/// names `source`, the line and the key. Both the one-axis and the
/// three-axis scenes are read through it.
pub fn parse_toml<T: serde::de::DeserializeOwned>(
    text: &str,
    source: &str,
    sets: &[String],
) -> Result<T, Error> {
    let line_of = |e: &toml::de::Error| {
        e.span()
            .map(|s| {
                format!(
                    "line {}: ",
                    text[..s.start.min(text.len())].matches('\n').count() + 1
                )
            })
            .unwrap_or_default()
    };
    let mut table: toml::Table = toml::from_str(text)
        .map_err(|e| Error::Scene(format!("{source}: {}{}", line_of(&e), e.message())))?;
    let value: T = if sets.is_empty() {
        // serde_path_to_error names the field; toml's span alone points
        // at the enclosing table for a bad value inside one.
        let de = toml::Deserializer::parse(text)
            .map_err(|e| Error::Scene(format!("{source}: {}{}", line_of(&e), e.message())))?;
        serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            let (line, key) = locate(text, &path, inner.message())
                .map(|(l, k)| (format!("line {l}: "), format!("{k}: ")))
                .unwrap_or_else(|| {
                    let field = if path.is_empty() || path == "." {
                        String::new()
                    } else {
                        format!("{path}: ")
                    };
                    (line_of(&inner), field)
                });
            Error::Scene(format!("{source}: {line}{key}{}", inner.message()))
        })?
    } else {
        for s in sets {
            apply_set(&mut table, s)?;
        }
        // The overridden scene has no lines of its own: name the key.
        let merged = toml::to_string(&table).map_err(|e| Error::Scene(format!("{source}: {e}")))?;
        toml::from_str(&merged).map_err(|e| {
            let key = e
                .span()
                .and_then(|s| {
                    merged[..s.start.min(merged.len())]
                        .lines()
                        .last()
                        .map(str::to_string)
                })
                .unwrap_or_default();
            let quoted = e.message().split('"').nth(1).unwrap_or("\u{0}");
            if let Some(set) = sets
                .iter()
                .find(|s| s.split_once('=').is_some_and(|(_, v)| v.trim() == quoted))
            {
                return Error::Scene(format!("{source}: --set {set}: {}", e.message()));
            }
            let near = if key.trim().is_empty() {
                String::new()
            } else {
                format!(" (at `{}`)", key.trim())
            };
            Error::Scene(format!("{source} with --set: {}{near}", e.message()))
        })?
    };
    Ok(value)
}
