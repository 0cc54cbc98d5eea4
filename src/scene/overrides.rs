//! `--set key=value` overrides applied to the scene's TOML tree before it is read, so a
//! study or a user can change one value without editing the file. A dotted key walks
//! tables; inside an array of tables (`groups`) a segment selects the element by its
//! `name` or by its index. The value is read as TOML (`3.0e6`, `true`, `"strain"`,
//! `[0.0, 1.0]`); a bare word is taken as a string.

use super::SceneError;
use toml::{Table, Value};

/// Apply every `key=value` in order.
pub fn apply_overrides(root: &mut Table, overrides: &[String]) -> Result<(), SceneError> {
    for o in overrides {
        let (key, raw) = o.split_once('=').ok_or_else(|| SceneError::Override {
            key: o.clone(),
            message: "expected key=value, e.g. material.E=3.0e10".into(),
        })?;
        let key = key.trim();
        let raw = raw.trim();
        // an integer beyond TOML's range would otherwise be taken as a string
        let digits = raw.strip_prefix(['-', '+']).unwrap_or(raw);
        if !digits.is_empty()
            && digits.bytes().all(|b| b.is_ascii_digit())
            && raw.parse::<i64>().is_err()
        {
            return Err(SceneError::Override {
                key: key.into(),
                message: format!(
                    "{raw} is beyond the integers a scene can hold ({} to {}, TOML's range)",
                    i64::MIN,
                    i64::MAX
                ),
            });
        }
        let value = parse_value(raw);
        set_path(root, key, value)?;
    }
    Ok(())
}

fn parse_value(raw: &str) -> Value {
    let doc = format!("v = {raw}");
    match doc.parse::<Table>() {
        Ok(mut t) => t.remove("v").unwrap_or_else(|| Value::String(raw.into())),
        Err(_) => Value::String(raw.into()),
    }
}

fn set_path(root: &mut Table, key: &str, value: Value) -> Result<(), SceneError> {
    let parts: Vec<&str> = key.split('.').collect();
    if parts.iter().any(|p| p.is_empty()) {
        return Err(SceneError::Override {
            key: key.into(),
            message: "empty key segment".into(),
        });
    }
    let mut node: &mut Value = root.entry(parts[0].to_string()).or_insert_with(|| {
        if parts.len() > 1 {
            Value::Table(Table::new())
        } else {
            Value::Boolean(false)
        }
    });
    for (depth, part) in parts.iter().enumerate().skip(1) {
        let here = parts[..depth].join(".");
        node = match node {
            Value::Table(t) => t
                .entry(part.to_string())
                .or_insert_with(|| Value::Table(Table::new())),
            Value::Array(items) => {
                let idx = items
                    .iter()
                    .position(|it| it.get("name").and_then(Value::as_str) == Some(part))
                    .or_else(|| part.parse::<usize>().ok().filter(|i| *i < items.len()))
                    .ok_or_else(|| SceneError::Override {
                        key: key.into(),
                        message: format!(
                            "`{here}` is a list: select an element by its name or index, \
                             `{part}` is neither"
                        ),
                    })?;
                &mut items[idx]
            }
            _ => {
                return Err(SceneError::Override {
                    key: key.into(),
                    message: format!("`{here}` is a value, not a table"),
                })
            }
        };
    }
    *node = value;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overrides_reach_tables_and_named_array_elements() {
        let mut t: Table = r#"
            [material]
            E = 1.0
            [[groups]]
            name = "top"
            [groups.load]
            displacement = 1.0
        "#
        .parse()
        .unwrap();
        apply_overrides(
            &mut t,
            &[
                "material.E=3.0e10".into(),
                "groups.top.load.displacement=-2e-4".into(),
                "material.plane=strain".into(),
            ],
        )
        .unwrap();
        assert_eq!(t["material"]["E"].as_float(), Some(3.0e10));
        assert_eq!(t["material"]["plane"].as_str(), Some("strain"));
        assert_eq!(
            t["groups"][0]["load"]["displacement"].as_float(),
            Some(-2e-4)
        );
        assert!(apply_overrides(&mut t, &["groups.bottom.fix=1".into()]).is_err());
        assert!(apply_overrides(&mut t, &["material.E".into()]).is_err());
    }
}
