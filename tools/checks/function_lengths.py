#!/usr/bin/env python3
"""Lists C++ functions longer than a limit (lines from the opening to the closing brace).

Usage: function_lengths.py [--max N] DIR...   exit 1 when a function is over N lines (default 80).

A function body is a '{' at namespace or class scope whose preceding code ends with ')' (optionally
followed by const, override, noexcept, a trailing return type or a constructor's initialiser list).
Comments and string literals are blanked first. Lambdas count towards the function that holds them.
"""
import argparse
import pathlib
import re
import sys

SCOPE_OPENERS = re.compile(r'\b(namespace|class|struct|union|enum)\b[^;{()]*$')


def blank_comments_and_strings(text):
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith('//', i):
            j = text.find('\n', i)
            j = n if j < 0 else j
            out.append(' ' * (j - i)); i = j
        elif text.startswith('/*', i):
            j = text.find('*/', i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r'[^\n]', ' ', text[i:j])); i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(')' + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r'[^\n]', ' ', text[i:j])); i = j
        elif c in '"\'':
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == '\\' else 1
            j = min(j + 1, n)
            out.append(c + ' ' * (j - i - 2) + c if j - i >= 2 else text[i:j]); i = j
        else:
            out.append(c); i += 1
    return ''.join(out)


def function_spans(text):
    """Yields (name, first_line, last_line) of function bodies at namespace/class scope."""
    code = blank_comments_and_strings(text)
    stack = []  # entries: 'scope' | 'function' | 'block'
    function_start = None
    last_stmt_end = 0
    for i, c in enumerate(code):
        if c == '{':
            head = code[last_stmt_end:i]
            head_flat = ' '.join(head.split())
            inside_function = 'function' in stack
            if inside_function:
                stack.append('block')
            elif SCOPE_OPENERS.search(head_flat) or head_flat.endswith('=') or head_flat == '' or \
                    head_flat.startswith('extern'):
                stack.append('scope')
            elif re.search(r'\)\s*(const|override|final|noexcept|mutable|->[^{]*|:[^{]*|\s)*$', head_flat):
                name = re.findall(r'([~\w:]+)\s*\(', head_flat)
                function_start = (name[0] if name else '?', code.count('\n', 0, i) + 1)
                stack.append('function')
            else:
                stack.append('block')
            last_stmt_end = i + 1
        elif c == '}':
            kind = stack.pop() if stack else 'scope'
            if kind == 'function' and function_start:
                yield function_start[0], function_start[1], code.count('\n', 0, i) + 1
                function_start = None
            last_stmt_end = i + 1
        elif c == ';':
            last_stmt_end = i + 1
        elif c == ':' and not stack_has_function(stack) and code[i - 1:i + 1] != '::' and code[i:i + 2] != '::':
            # access specifiers (public:) end a head; a constructor's initialiser list does not
            head = ' '.join(code[last_stmt_end:i].split())
            if head in ('public', 'private', 'protected'):
                last_stmt_end = i + 1


def stack_has_function(stack):
    return 'function' in stack


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('--max', type=int, default=80)
    parser.add_argument('dirs', nargs='+')
    args = parser.parse_args()
    over = []
    for d in args.dirs:
        for path in sorted(pathlib.Path(d).rglob('*')):
            if path.suffix not in ('.cpp', '.hpp', '.h', '.cc'):
                continue
            for name, first, last in function_spans(path.read_text(errors='replace')):
                if last - first + 1 > args.max:
                    over.append((last - first + 1, f'{path}:{first}', name))
    for length, where, name in sorted(over, reverse=True):
        print(f'{where}: {name} is {length} lines (limit {args.max})')
    return 1 if over else 0


if __name__ == '__main__':
    sys.exit(main())
