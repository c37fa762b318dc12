#!/usr/bin/env python3
"""The docs match the code: every source path, C++ name and command-line
option that the docs name exists.

  check_docs.py C3PO_EXE SOURCE_DIR [DOC ...]
  (default docs: README.md, docs/*.md, annotations/README.md, plugins/*/README.md)

Checked, per doc line (the message names FILE:LINE and the item):
- paths in backticks or markdown links whose first folder is one of the
  repository's (libc3po, cli, tests, ...), a libc3po layer or a plugin, or
  c3po/ (the include prefix): a file whose path ends with it, or a file of
  that name below its folders in that order (`method/free_space.cpp`), or a
  path a CMake file names (generated: c3po/base/version.hpp);
- CamelCase names in backticks (`CheckWeakMotion`, `GlobalUniquenessOptions::reestimate`):
  the name (the last part) is a word of the C++ or CMake sources;
- snake_case names in backticks (JSON keys such as `free_space_shift_px`,
  fields, test names): a word of the sources or scripts, a file's name
  without extension, or a word of the doc's own fenced examples;
- options after `c3po COMMAND [SUBCOMMAND]`, in the docs and in the commands'
  own --help examples: listed by that command's --help;
  an option in backticks elsewhere (`--reestimate`): listed by some command's;
- docs named in the docs and in every source, script and message: they
  exist; section references (docs/method.md "Weak motion"): that doc has a
  heading or a bold lead that begins with the title.
Exit 0 when all exist, 1 with one line per missing item, 2 on bad usage.
"""
import os
import re
import subprocess
import sys

SKIP_DIRS = {".git", "node_modules", ".cache"}
SOURCE_EXT = (".hpp", ".cpp", ".h", ".sh", ".py", ".cmake", ".txt", ".js", ".in")


def repo_files(root):
    files = []
    for folder, dirs, names in os.walk(root):
        dirs[:] = [d for d in dirs if d not in SKIP_DIRS and not d.startswith("build")]
        for name in names:
            files.append(os.path.relpath(os.path.join(folder, name), root).replace(os.sep, "/"))
    return files


def first_folders(files):
    """Folder names a checked path may start with."""
    top = {f.split("/")[0] for f in files if "/" in f}
    layers = {f.split("/")[1] for f in files if f.startswith(("libc3po/", "plugins/")) and f.count("/") >= 2}
    return top | layers | {"c3po"}


def in_order(wanted, folders):
    it = iter(folders)
    return all(w in it for w in wanted)


def path_exists(path, files, cmake_text):
    parts = path.split("/")
    for f in files:
        if f == path or f.endswith("/" + path):
            return True
        have = f.split("/")
        if have[-1] == parts[-1] and in_order(parts[:-1], have[:-1]):
            return True
    return path in cmake_text


def check_paths(doc, lineno, line, files, folders, cmake_text, report):
    spans = re.findall(r"`([^`\s]+)`", line) + re.findall(r"\]\(([^)\s#]+)", line)
    for span in spans:
        span = span.rstrip(".,:;")
        if "/" not in span or not span.endswith(SOURCE_EXT + (".md",)):
            continue
        if span.split("/")[0] not in folders or "*" in span or "<" in span:
            continue
        if re.fullmatch(r"docs/[A-Za-z_]+\.md", span):
            continue   # check_sections reports a missing doc
        if not path_exists(span, files, cmake_text):
            report(doc, lineno, f"names `{span}`, which is not a file of the repository")


CAMEL_CASE = re.compile(r"`([A-Z][A-Za-z0-9]*[a-z0-9][A-Z][A-Za-z0-9]*(?:::[A-Za-z_][A-Za-z0-9_]*)?)(?:\(\))?`")


def check_names(doc, lineno, line, code_words, report):
    for span in CAMEL_CASE.findall(line):
        name = span.split("::")[-1]
        if name not in code_words:
            report(doc, lineno, f"names `{span}`, which no C++ or CMake source defines or uses")


def check_keys(doc, lineno, line, known_words, report):
    """snake_case names in backticks: JSON keys, fields, test names."""
    for span in re.findall(r"`([a-z][a-z0-9]*(?:_[a-z0-9]+)+)`", line):
        if span not in known_words:
            report(doc, lineno, f"names `{span}`, which no source, file name or example of the doc has")


def example_words(text):
    """Words of a doc's fenced examples (folders and files the examples make)."""
    blocks = re.findall(r"^```[^\n]*\n(.*?)^```", text, re.M | re.S)
    return set(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", "\n".join(blocks)))


def subcommands(help_text):
    """The names listed under "Subcommands:" in a CLI11 help text."""
    section = help_text.split("Subcommands:", 1)[1].split("\n\n", 1)[0] if "Subcommands:" in help_text else ""
    return set(re.findall(r"^  ([a-z][a-z-]*) ", section, re.M))


class Commands:
    def __init__(self, exe):
        self.exe = exe
        self.helps = {}
        top = self.help([])
        if top is None:
            sys.exit(f"check_docs.py: {exe}: --help failed")
        self.commands = subcommands(top)
        self.bench = subcommands(self.help(["bench"]) or "") if "bench" in self.commands else set()

    def help(self, words):
        key = " ".join(words)
        if key not in self.helps:
            run = subprocess.run([self.exe] + words + ["--help"], capture_output=True, text=True)
            self.helps[key] = run.stdout if run.returncode == 0 else None
        return self.helps[key]

    def every_option(self):
        """The options of every command and bench subcommand."""
        known = set()
        for command in self.commands:
            known |= self.options([command]) or set()
        for bench in self.bench:
            known |= self.options(["bench", bench]) or set()
        return known

    def options(self, words):
        """The options the help lists (the first column of its option lines, not its examples)."""
        text = self.help(words)
        if text is None:
            return None
        names = set()
        for first in re.findall(r"^ +(-\S+)", text, re.M):
            names |= set(re.findall(r"--[a-z0-9][a-z0-9-]*", first))
        return names


def check_options(doc, lineno, line, commands, report):
    for match in re.finditer(r"(?<![\w/.-])c3po ([a-z][a-z-]*)(?: ([a-z][a-z-]*))?([^`|;&#]*)", line):
        command, word, rest = match.group(1), match.group(2), match.group(3)
        if command not in commands.commands:
            continue
        words = [command]
        if command == "bench" and word in commands.bench:
            words.append(word)
        elif word:
            rest = " " + word + rest
        known = commands.options(words)
        if known is None:
            report(doc, lineno, f"`c3po {' '.join(words)} --help` fails")
            continue
        for option in re.findall(r"(?<![\w-])--[a-z0-9][a-z0-9-]*", rest):
            if option not in known:
                report(doc, lineno,
                       f"gives `c3po {' '.join(words)}` the option {option}, which its --help does not list")


def check_named_options(doc, lineno, line, every_option, report):
    for span in re.findall(r"`(--[a-z0-9][a-z0-9-]*)[^`]*`", line):
        if span not in every_option:
            report(doc, lineno, f"names the option {span}, which no command's --help lists")


def default_docs(root):
    """README.md, docs/*.md and the READMEs of annotations/ and each plugin (not
    CHANGELOG.md, which keeps old names, nor third_party_notes/, which name the
    libraries' own APIs)."""
    docs = [os.path.join(root, "README.md"), os.path.join(root, "annotations", "README.md")]
    docs += sorted(os.path.join(root, "docs", n) for n in os.listdir(os.path.join(root, "docs")) if n.endswith(".md"))
    plugins = os.path.join(root, "plugins")
    docs += sorted(os.path.join(plugins, n, "README.md") for n in os.listdir(plugins)
                   if os.path.isfile(os.path.join(plugins, n, "README.md")))
    return docs


def section_titles(text):
    """Headings (outside fenced examples) and bold leads of a doc."""
    prose = re.sub(r"^```.*?^```", "", text, flags=re.M | re.S)
    return [h.strip() for h in re.findall(r"^#+ (.*)$", prose, re.M)] + re.findall(r"\*\*([^*]+)\*\*", prose)


def doc_titles(root, files):
    titles = {}
    for f in files:
        if f.startswith("docs/") and f.endswith(".md"):
            with open(os.path.join(root, f), errors="replace") as stream:
                titles[f] = section_titles(stream.read())
    return titles


def check_sections(paths, titles, report):
    """References such as docs/method.md "Weak motion" in the files at `paths`."""
    reference = re.compile(r'(docs/[A-Za-z_]+\.md)[,:]?\s*\\?"([^"\\]+)\\?"')
    mention = re.compile(r"(?<![\w/.-])docs/[A-Za-z_]+\.md")   # another project's: bop_toolkit/docs/...
    for path in paths:
        with open(path, errors="replace") as stream:
            for lineno, line in enumerate(stream, 1):
                for doc in mention.findall(line):
                    if doc not in titles:
                        report(path, lineno, f"names {doc}, which is not a doc of the repository")
                for doc, title in reference.findall(line):
                    if doc in titles and not any(t.startswith(title) for t in titles[doc]):
                        report(path, lineno, f'refers to {doc} "{title}", which has no such section')


def main(argv):
    if len(argv) < 3:
        print("usage: check_docs.py C3PO_EXE SOURCE_DIR [DOC ...]", file=sys.stderr)
        return 2
    exe, root = argv[1], os.path.abspath(argv[2])
    docs = argv[3:] or default_docs(root)
    files = repo_files(root)
    folders = first_folders(files)
    texts = {f: open(os.path.join(root, f), errors="replace").read() for f in files
             if f.endswith((".hpp", ".cpp", ".h", ".cmake", ".in", "CMakeLists.txt", ".sh", ".py", ".js"))}

    def words(names):
        return set(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", "\n".join(texts[f] for f in names)))

    code_words = words(f for f in texts if not f.endswith((".sh", ".py", ".js")))
    cmake_text = "\n".join(text for f, text in texts.items() if f.endswith((".cmake", "CMakeLists.txt")))
    stems = {os.path.splitext(f.split("/")[-1])[0] for f in files}
    source_words = code_words | words(f for f in texts if f.endswith((".sh", ".py", ".js"))) | stems
    commands = Commands(exe)
    every_option = commands.every_option()
    problems = []

    def report(doc, lineno, what):
        name = os.path.relpath(doc, root) if os.path.isabs(doc) else doc
        problems.append(f"{doc if name.startswith('..') else name}:{lineno}: {what}")

    for doc in docs:
        with open(doc, errors="replace") as stream:
            text = stream.read()
        known_words = source_words | example_words(text)
        for lineno, line in enumerate(text.splitlines(), 1):
            check_paths(doc, lineno, line, files, folders, cmake_text, report)
            check_names(doc, lineno, line, code_words, report)
            check_keys(doc, lineno, line, known_words, report)
            check_options(doc, lineno, line, commands, report)
            check_named_options(doc, lineno, line, every_option, report)
    if len(argv) == 3:   # the commands' own examples (the Example: lines of each --help)
        for words in [[c] for c in sorted(commands.commands)] + [["bench", b] for b in sorted(commands.bench)]:
            lines = (commands.help(words) or "").splitlines()
            examples = next((i for i, line in enumerate(lines) if line.startswith("Example")), len(lines))
            for lineno in range(examples + 1, len(lines) + 1):
                check_options(f"c3po {' '.join(words)} --help", lineno, lines[lineno - 1], commands, report)
    # Section references: in the given docs, or (checking the repository) in every doc, source and script.
    # (not tests/docs/: the check's own test writes references that must fail)
    referring = docs if len(argv) > 3 else [os.path.join(root, f) for f in files
                                            if f.endswith(SOURCE_EXT + (".md",)) and not f.startswith("tests/docs/")]
    check_sections(referring, doc_titles(root, files), report)
    for problem in problems:
        print(problem)
    print(f"check_docs.py: {len(docs)} docs, {len(problems)} items that do not exist", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
