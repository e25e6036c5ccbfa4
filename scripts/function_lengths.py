#!/usr/bin/env python3
"""Lines of every C++ function definition (signature to closing brace), longest first.

usage: scripts/function_lengths.py [--min LINES] [--top N] FILE_OR_DIR...

A brace matcher, not a parser: comments, strings and character literals are blanked, then a '{' outside
any function opens a function when the text before it ends in ')' plus qualifiers (const, override, an
initializer list, a trailing return type) and is not a control statement. Lambdas and local classes count
towards the function they are in.
"""
import argparse
import os
import re
import sys

CONTROL = re.compile(r"^\s*(if|for|while|switch|catch|do|else)\b")
SCOPE = re.compile(r"\b(namespace|class|struct|union|enum)\b[^()]*$|^\s*extern\s+\"")


def blank_comments_and_strings(text):
    """Replaces comments, string and char literals by spaces, keeping newlines (and line numbers)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == 'R' and text.startswith('R"', i):
            delim_end = text.find("(", i)
            delim = text[i + 2:delim_end]
            j = text.find(")" + delim + '"', delim_end)
            j = n if j < 0 else j + len(delim) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            # a digit separator (1'000) is not a character literal
            if c == "'" and i > 0 and text[i - 1].isalnum() and text[i - 1] not in "uUL":
                out.append(c)
                i += 1
                continue
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def function_name(header):
    """The qualified name before the parameter list of a function header."""
    flat = " ".join(header.split())
    depth, end = 0, -1
    for k, ch in enumerate(flat):
        if ch == "(":
            if depth == 0 and end < 0:
                end = k
            depth += 1
        elif ch == ")":
            depth -= 1
    if end < 0:
        return flat[-60:]
    match = re.search(r"((?:[A-Za-z_~][\w]*(?:<[^()]*>)?::)*(?:operator\s*\S+|~?[A-Za-z_]\w*))\s*$",
                      flat[:end])
    return match.group(1) if match else flat[:end][-60:]


def functions_in(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        text = blank_comments_and_strings(f.read())
    # Preprocessor lines say nothing about braces here.
    text = re.sub(r"(?m)^\s*#.*(?:\\\n.*)*$", lambda m: re.sub(r"[^\n]", " ", m.group(0)), text)
    results = []
    stack = []  # per open brace: "scope", "function" or "block"
    statement_start = 0  # offset where the text before the next '{' begins
    function_start = None
    for k, ch in enumerate(text):
        if ch == "{":
            inside_function = "function" in stack
            header = text[statement_start:k]
            kind = "block"
            if not inside_function:
                stripped = header.strip()
                if SCOPE.search(stripped) or stripped.endswith("=") or not stripped:
                    kind = "scope"
                elif ")" in stripped and not CONTROL.match(stripped) and not re.search(r"\]\s*\(", stripped):
                    kind = "function"
                    lead = len(header) - len(header.lstrip())
                    function_start = (statement_start + lead, function_name(stripped))
                else:
                    kind = "scope"
            stack.append(kind)
            statement_start = k + 1
        elif ch == "}":
            kind = stack.pop() if stack else "scope"
            if kind == "function" and "function" not in stack and function_start:
                first = text.count("\n", 0, function_start[0]) + 1
                last = text.count("\n", 0, k) + 1
                results.append((last - first + 1, path, first, function_start[1]))
                function_start = None
            statement_start = k + 1
        elif ch == ";":
            statement_start = k + 1
        elif ch == ":" and "function" not in stack:
            # access specifiers (public:) end a statement; a '::' does not
            before = text[statement_start:k].strip()
            if before in ("public", "private", "protected") and text[k + 1:k + 2] != ":":
                statement_start = k + 1
    return results


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("paths", nargs="+")
    parser.add_argument("--min", type=int, default=0, help="only functions of at least this many lines")
    parser.add_argument("--top", type=int, default=0, help="only the N longest")
    args = parser.parse_args()
    files = []
    for path in args.paths:
        if os.path.isdir(path):
            for root, _, names in os.walk(path):
                files += [os.path.join(root, n) for n in names if n.endswith((".cpp", ".h", ".hpp", ".cc"))]
        else:
            files.append(path)
    found = []
    for path in sorted(files):
        found += functions_in(path)
    found.sort(key=lambda r: (-r[0], r[1], r[2]))
    if args.min:
        found = [r for r in found if r[0] >= args.min]
    if args.top:
        found = found[:args.top]
    for lines, path, line, name in found:
        print(f"{lines:5d}  {path}:{line}  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
