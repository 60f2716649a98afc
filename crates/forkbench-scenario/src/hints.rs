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

/// For a parse error that a key is missing: where the key stands instead. `at` is where
/// the error points (a non-empty span): on a `[table]` header the key is that table's,
/// and a key of the same name in one of its sub-tables is the sub-table's own; without
/// it the key is a top-level one that a `[table]` header above swallowed (TOML puts
/// every key after a header into that table).
pub(super) fn misplaced_key(text: &str, message: &str, at: Option<usize>) -> Option<String> {
    let key = message.split("missing field `").nth(1)?.split('`').next()?;
    if let Some(owner) = at.and_then(|i| owner_table(text, i)) {
        return in_sub_table(text, key, &owner);
    }
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

/// The table a header at byte `i` names: the whole header, or (an error on one of a
/// dotted header's parts) the tables up to that part.
fn owner_table(text: &str, i: usize) -> Option<String> {
    let start = text.get(..i)?.rfind('\n').map_or(0, |n| n + 1);
    let line = text[start..].lines().next()?;
    let lead = line.len() - line.trim_start().len();
    let header = line.trim();
    if !header.starts_with('[') {
        return None;
    }
    let inner = header.trim_start_matches('[');
    let inner = inner.split(']').next()?;
    let brackets = header.len() - header.trim_start_matches('[').len();
    let at = (i - start).checked_sub(lead + brackets);
    let name = match at {
        Some(off) if off < inner.len() => {
            let end = inner[off..].find('.').map_or(inner.len(), |d| off + d);
            &inner[..end]
        }
        _ => inner,
    };
    Some(name.split('.').map(str::trim).collect::<Vec<_>>().join("."))
}

/// When `[owner]` lacks `key` and one of its sub-tables has a `key` of its own, says so.
fn in_sub_table(text: &str, key: &str, owner: &str) -> Option<String> {
    let mut table: Option<(usize, String)> = None;
    for (n, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.starts_with('[') {
            let name = t.trim_matches(|c| c == '[' || c == ']');
            let name = name.split('.').map(str::trim).collect::<Vec<_>>().join(".");
            table = Some((n + 1, name));
        } else if let Some((_, sub)) = &table
            && sub.starts_with(&format!("{owner}."))
            && t.split('=').next().map(str::trim) == Some(key)
        {
            return Some(format!(
                "[{owner}] has no `{key}` of its own: the `{key}` at line {} belongs to \
                 [{sub}], a table of its own; write [{owner}]'s `{key}` under a [{owner}] \
                 header, before [{sub}]",
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
        let hint = misplaced_key(text, "missing field `start`", None).expect("hint");
        assert!(
            hint.contains("line 5 inside [tracker] (opened at line 3)"),
            "{hint}"
        );
        assert_eq!(misplaced_key(text, "missing field `pallet`", None), None);
    }

    /// A table's own key missing while its sub-table has one: the hint names the table
    /// that lacks it, not "top-level keys".
    #[test]
    fn a_sub_table_s_key_is_not_taken_for_its_parent_s() {
        let text = "name = \"x\"\n[sensors.pallet]\nlatency_s = 0.03\n[sensors.pallet.detector]\nkind = \"face_fit\"\n";
        let at = text.find("[sensors.pallet]");
        let hint = misplaced_key(text, "missing field `kind`", at).expect("hint");
        assert!(
            hint.starts_with("[sensors.pallet] has no `kind` of its own")
                && hint.contains("line 5 belongs to [sensors.pallet.detector]"),
            "{hint}"
        );
        // The implicit parent of a dotted header, the error on its `pallet` part.
        let text = "name = \"x\"\n[sensors.pallet.detector]\nkind = \"face_fit\"\n";
        let at = text.find("pallet.detector").map(|i| i + 1);
        let hint = misplaced_key(text, "missing field `kind`", at).expect("hint");
        assert!(hint.starts_with("[sensors.pallet] has no `kind`"), "{hint}");
    }
}
