//! Text from users and child processes made safe for each output: Markdown cells, CSV cells (no spreadsheet formulas), terminals.

/// Control characters (C0, DEL, C1) written as visible escapes (`\u{1b}`), so a message
/// cannot move a terminal's cursor, fake a line or hide text.
pub fn visible(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_control() && c != '\n' && c != '\t' {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// One line of visible text: line breaks and tabs become spaces as well.
pub fn one_line(text: &str) -> String {
    visible(&text.replace(['\n', '\r', '\t'], " "))
}

/// Text inside HTML or XML (an element's text or a double-quoted attribute): control
/// characters as visible escapes ([`visible`], so nothing XML 1.0 forbids remains), and
/// `&`, `<`, `>` and `"` as entities. The one escaping of the report, SVG and JUnit.
pub fn markup(text: &str) -> String {
    visible(text)
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A Markdown table cell: one line, `|` escaped, and HTML's special characters as
/// entities (Markdown renderers pass raw HTML through).
pub fn md_cell(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in one_line(text).chars() {
        match c {
            '|' => out.push_str("\\|"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            c => out.push(c),
        }
    }
    out
}

/// A CSV text cell: control characters escaped, and a leading `=`, `+`, `-`, `@`, tab or
/// carriage return neutralised with a `'` so a spreadsheet shows it as text (OWASP's rule
/// against formula injection).
pub fn csv_text(text: &str) -> String {
    let starts_formula = text
        .chars()
        .next()
        .is_some_and(|c| matches!(c, '=' | '+' | '-' | '@' | '\t' | '\r'));
    let body = visible(&text.replace(['\t', '\r'], " "));
    if starts_formula {
        format!("'{body}")
    } else {
        body
    }
}

/// Numbers written out with more than 20 digits (`1e300` printed in full, as Rust and
/// serde print floats) in scientific notation; seeds (at most 20 digits) are kept.
pub fn compact_numbers(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let chars: Vec<char> = text.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        if !chars[i].is_ascii_digit() {
            out.push(chars[i]);
            i += 1;
            continue;
        }
        let start = i;
        while i < chars.len()
            && (chars[i].is_ascii_digit()
                || (chars[i] == '.' && chars.get(i + 1).is_some_and(char::is_ascii_digit)))
        {
            i += 1;
        }
        let token: String = chars[start..i].iter().collect();
        let digits = token.chars().filter(char::is_ascii_digit).count();
        match token.parse::<f64>() {
            Ok(v) if digits > 20 => out.push_str(&short_sci(v)),
            _ => out.push_str(&token),
        }
    }
    out
}

/// `v` as `d.ddddde±N`, trailing zeros of the mantissa dropped.
fn short_sci(v: f64) -> String {
    let s = format!("{v:.5e}");
    match s.split_once('e') {
        Some((m, e)) if m.contains('.') => {
            format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
        }
        _ => s,
    }
}

/// `text` with every character other than ASCII letters, digits, '-' and '_' replaced by
/// '_': a name that can neither leave its folder nor fail a write as a file name.
pub fn safe_file_stem(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hostile_text_is_neutralised() {
        assert_eq!(csv_text("=cmd|' /C calc'!A0"), "'=cmd|' /C calc'!A0");
        for s in ["+cmd", "-2+3", "@SUM(A1)", "\tx", "\rx"] {
            assert!(csv_text(s).starts_with('\''), "{s:?}");
        }
        assert_eq!(csv_text("bspline"), "bspline");
        assert_eq!(visible("a\u{1b}[2Kb\u{7}\0"), "a\\u{1b}[2Kb\\u{7}\\u{0}");
        assert_eq!(
            markup("<a href=\"x\">R&D</a>\u{1b}"),
            "&lt;a href=&quot;x&quot;&gt;R&amp;D&lt;/a&gt;\\u{1b}"
        );
        assert_eq!(
            md_cell("a|b\n# head <script>"),
            "a\\|b # head &lt;script&gt;"
        );
    }
}
