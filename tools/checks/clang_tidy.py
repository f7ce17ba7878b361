#!/usr/bin/env python3
"""Runs clang-tidy (the checks of the repository's .clang-tidy) over the project's own sources.

Usage: clang_tidy.py --build-dir BUILD [--source-dir SRC] [--clang-tidy EXE] [-j N] [--no-cache] [REGEX]

The files are the translation units of BUILD/compile_commands.json that lie under SRC and not under
BUILD (generated code is left out); REGEX, when given, keeps those whose path relative to SRC matches it.
Headers are checked through the files that include them, when they lie in the project's folders
(runtime/, stages/, tools/, tests/). Prints every finding and a summary with the time taken; exit 1 on any
finding (the checks are errors), 2 when clang-tidy cannot run.

Parsing dominates (a few seconds a file with Eigen, PCL and OpenCV), so a file that passed is not checked
again while nothing it sees has changed: BUILD/clang-tidy-cache/ keeps one empty file per pass, named by
a hash of the file as the compiler preprocesses it (every header it includes), its flags, the
.clang-tidy and the clang-tidy version. Preprocessing costs a small part of a check. --no-cache checks
every file.
"""
import argparse
import concurrent.futures
import hashlib
import json
import os
import pathlib
import re
import shlex
import shutil
import subprocess
import sys
import time

PROJECT_FOLDERS = ('runtime', 'stages', 'tools', 'tests')


def escape(text):
    """The path as a literal in clang-tidy's (POSIX extended) regular expressions."""
    return re.sub(r'([.^$|()\[\]{}*+?\\])', r'\\\1', text)


def project_sources(build_dir, source_dir, pattern):
    """{path: compile command entry} of the project's translation units (the first entry of a file)."""
    with open(build_dir / 'compile_commands.json') as f:
        entries = json.load(f)
    files = {}
    for entry in entries:
        path = pathlib.Path(entry['directory'], entry['file']).resolve()
        if build_dir in path.parents or source_dir not in path.parents:
            continue
        if path.suffix != '.cpp':
            continue
        relative = path.relative_to(source_dir).as_posix()
        if pattern and not re.search(pattern, relative):
            continue
        files.setdefault(path, entry)
    return dict(sorted(files.items()))


def preprocessed(entry):
    """The file as the compiler of the build sees it after the preprocessor, or None if that fails."""
    args = entry['arguments'] if 'arguments' in entry else shlex.split(entry['command'])
    if '-o' in args:
        k = args.index('-o')
        args = args[:k] + args[k + 2:]
    args = [a for a in args if a != '-c'] + ['-E']
    result = subprocess.run(args, cwd=entry['directory'], capture_output=True)
    return result.stdout if result.returncode == 0 else None


def cache_key(setup, path, entry):
    """The name of the file's pass in the cache, or None when it cannot be preprocessed."""
    text = preprocessed(entry)
    if text is None:
        return None
    digest = hashlib.sha256()
    for part in setup + [str(path).encode(), json.dumps(entry, sort_keys=True).encode(), text]:
        digest.update(hashlib.sha256(part).digest())
    return digest.hexdigest()


def findings(result):
    """What clang-tidy said, without its counts of the warnings it did not show (system headers)."""
    lines = (result.stdout + result.stderr).strip().splitlines()
    return '\n'.join(line for line in lines
                     if not re.match(r'^\d+ warnings? (and \d+ errors? )?generated\.$', line)
                     and not line.startswith(('Suppressed ', 'Use -header-filter', 'Use -system-headers')))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--build-dir', required=True, type=pathlib.Path)
    parser.add_argument('--source-dir', type=pathlib.Path, default=pathlib.Path(__file__).resolve().parents[2])
    parser.add_argument('--clang-tidy', default='clang-tidy')
    parser.add_argument('-j', type=int, default=os.cpu_count() or 1, help='files checked at once')
    parser.add_argument('--no-cache', action='store_true', help='check every file, also those that passed before')
    parser.add_argument('regex', nargs='?', help='only files whose path (relative to the source dir) matches')
    args = parser.parse_args()

    build_dir, source_dir = args.build_dir.resolve(), args.source_dir.resolve()
    if not (build_dir / 'compile_commands.json').is_file():
        print(f'clang-tidy: no {build_dir}/compile_commands.json (configure with CMAKE_EXPORT_COMPILE_COMMANDS)')
        return 2
    if not shutil.which(args.clang_tidy):
        print(f'clang-tidy: {args.clang_tidy} not found (Debian: apt-get install clang-tidy; tools/setup does)')
        return 2
    files = project_sources(build_dir, source_dir, args.regex)
    if not files:
        print('clang-tidy: no project source in the compilation database')
        return 2

    folders = '|'.join(PROJECT_FOLDERS)
    config = source_dir / '.clang-tidy'
    command = [args.clang_tidy, '-p', str(build_dir), '--quiet', f'--config-file={config}',
               f'--header-filter=^{escape(str(source_dir))}/({folders})/',
               # The database holds gcc's flags: clang does not know some of its warnings, and its own
               # warnings are the compiler's business (gcc's -Werror), not findings of these checks.
               '--extra-arg=-Wno-unknown-warning-option', '--extra-arg=-Wno-error']
    version = subprocess.run([args.clang_tidy, '--version'], capture_output=True, text=True).stdout
    # Everything a result depends on but the file itself.
    setup = [version.encode(), config.read_bytes(), ' '.join(command).encode()]
    cache = build_dir / 'clang-tidy-cache'
    cache.mkdir(exist_ok=True)

    def run(item):
        path, entry = item
        start = time.monotonic()
        key = None if args.no_cache else cache_key(setup, path, entry)
        if key and (cache / key).exists():
            return path, key, None, time.monotonic() - start
        result = subprocess.run(command + [str(path)], cwd=source_dir, capture_output=True, text=True)
        return path, key, result, time.monotonic() - start

    start = time.monotonic()
    failed, slowest, used, cached = [], [], set(), 0
    with concurrent.futures.ThreadPoolExecutor(max(1, args.j)) as pool:
        for path, key, result, seconds in pool.map(run, files.items()):
            used.add(key)
            slowest.append((seconds, path))
            if result is None:
                cached += 1
                continue
            output = findings(result)
            if result.returncode != 0 or output:
                failed.append(path)
                print(f'--- {path.relative_to(source_dir)}\n{output}', flush=True)
            elif key:
                (cache / key).touch()
    if not args.regex and not args.no_cache:  # passes of files as they no longer are
        for old in cache.iterdir():
            if old.name not in used:
                old.unlink()
    elapsed = time.monotonic() - start
    slowest.sort(reverse=True)
    print(f'clang-tidy: {len(files)} files ({cached} unchanged since they passed) in {elapsed:.0f} s with '
          f'-j{args.j}; slowest: ' +
          ', '.join(f'{path.relative_to(source_dir)} {seconds:.0f} s' for seconds, path in slowest[:3]))
    if failed:
        print(f'clang-tidy: findings in {len(failed)} file(s); the checks and why are in .clang-tidy')
        return 1
    print('clang-tidy: no finding')
    return 0


if __name__ == '__main__':
    sys.exit(main())
