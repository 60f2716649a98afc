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
            md_cell("a|b\n# head <script>"),
            "a\\|b # head &lt;script&gt;"
        );
    }
}
