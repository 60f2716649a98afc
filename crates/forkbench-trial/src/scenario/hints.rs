//! Help for likely slips in a scenario file: radians typed into a degrees key, and a top-level key that TOML put into the table above it.

/// `file:line: …` warnings for values of `*_deg` keys that look like radians: non-zero,
/// at most 2π in size, and not a multiple of half a degree (a heading of 1.79° is
/// possible, but 1.79 is far likelier to be 102.6° typed in radians).
pub(super) fn unit_warnings(text: &str, file: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let code = line.split('#').next().unwrap_or("");
        for (key, value) in deg_values(code) {
            let looks_rad = value != 0.0
                && value.abs() <= std::f64::consts::TAU + 1e-9
                && (value * 2.0).fract().abs() > 1e-9;
            if looks_rad {
                out.push(format!(
                    "{file}:{}: {key} = {value} looks like radians ({value} rad = {:.1}°); \
                     angles in scenario files are in degrees",
                    n + 1,
                    value.to_degrees()
                ));
            }
        }
    }
    out
}

/// Every `name_deg = number` on a line (inline tables included).
fn deg_values(code: &str) -> Vec<(String, f64)> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(i) = rest.find("_deg") {
        let before = &rest[..i];
        let key_start = before
            .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .map_or(0, |k| k + 1);
        let key = format!("{}_deg", &before[key_start..]);
        let after = rest[i + 4..].trim_start();
        if let Some(v) = after.strip_prefix('=') {
            let num: String = v
                .trim_start()
                .chars()
                .take_while(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E'))
                .collect();
            if let Ok(x) = num.parse::<f64>() {
                out.push((key, x));
            }
        }
        rest = &rest[i + 4..];
    }
    out
}

/// For a parse error that a top-level key is missing: where the key stands instead, when
/// a `[table]` header above it swallowed it (TOML puts every key after a header into that
/// table).
pub(super) fn misplaced_key(text: &str, message: &str) -> Option<String> {
    let key = message.split("missing field `").nth(1)?.split('`').next()?;
    let mut table: Option<(usize, &str)> = None;
    for (n, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.starts_with('[') {
            table = Some((n + 1, t));
        } else if let Some((header_line, header)) = table
            && t.split('=').next().map(str::trim) == Some(key)
        {
            return Some(format!(
                "`{key}` is written at line {} inside {header} (opened at line {header_line}): \
                 TOML puts every key after a [table] header into that table, so top-level keys \
                 must come before the first [table]",
                n + 1
            ));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radians_in_a_degrees_key_are_flagged_with_their_line() {
        let text = "start = { x_m = 0, y_m = 0, heading_deg = 1.79 }\npallet = { x_m = 8, y_m = 0, heading_deg = 90 }\n[tolerances]\nheading_deg = 3.0\npallet_rotation_deg = 1.5\n";
        let w = unit_warnings(text, "s.toml");
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(
            w[0].starts_with("s.toml:1: heading_deg = 1.79 looks like radians"),
            "{w:?}"
        );
    }

    #[test]
    fn a_key_swallowed_by_a_table_is_located() {
        let text = "name = \"x\"\nplanner = \"bspline\"\n[tracker]\nlookahead_m = 1\nstart = { x_m = 0 }\n";
        let hint = misplaced_key(text, "missing field `start`").expect("hint");
        assert!(
            hint.contains("line 5 inside [tracker] (opened at line 3)"),
            "{hint}"
        );
        assert_eq!(misplaced_key(text, "missing field `pallet`"), None);
    }
}
