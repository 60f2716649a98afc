"""The size limits of ARCHITECTURE.md: no function over 80 lines and no file over 500 lines in any
crate's src/ (tests, benches, examples and #[cfg(test)] modules aside for functions). Brace matching
on code with strings and comments blanked. Usage: check_limits.py [ROOT]; exit 1 naming each breach."""
import pathlib
import re
import sys

FN_LIMIT, FILE_LIMIT = 80, 500
FN = re.compile(r"\s*(pub(\([^)]*\))?\s+)?(const\s+)?(async\s+)?(unsafe\s+)?fn\s+(\w+)")


def code(line):
    return re.sub(r'"(\\.|[^"\\])*"', '""', line.split("//")[0])


def long_functions(path, lines):
    out, i = [], 0
    while i < len(lines):
        if re.match(r"\s*#\[cfg\(test\)\]", lines[i]):
            break  # the test module closes the file
        m = FN.match(lines[i])
        if not m:
            i += 1
            continue
        depth, j, started = 0, i, False
        while j < len(lines):
            c = code(lines[j])
            depth += c.count("{") - c.count("}")
            started |= "{" in c
            if (started and depth <= 0) or (not started and c.rstrip().endswith(";")):
                break
            j += 1
        if started and j - i + 1 > FN_LIMIT:
            out.append(f"{path}:{i + 1}: fn {m.group(6)} has {j - i + 1} lines (limit {FN_LIMIT})")
        i = j + 1 if started else i + 1
    return out


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    breaches = []
    files = list(root.glob("crates/*/src/**/*.rs")) + list(root.glob("python/src/**/*.rs"))
    for p in sorted(files):
        lines = p.read_text().splitlines()
        if len(lines) > FILE_LIMIT:
            breaches.append(f"{p}: {len(lines)} lines (limit {FILE_LIMIT})")
        breaches += long_functions(p, lines)
    print("\n".join(breaches) or f"limits ok: no fn over {FN_LIMIT} lines, no file over {FILE_LIMIT}")
    sys.exit(1 if breaches else 0)


main()
