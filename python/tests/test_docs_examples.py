"""Every C++ and Python code block of the README and the manual runs: each is
either a marked region of a program under examples/ (compiled and run by
ctest, or run by test_examples.py), or a doctest run here. A block edited
away from its example, or an example changed under its block, fails."""
import doctest
import glob
import os
import re
import textwrap

import pytest

import gssm

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
FENCE = re.compile(r"^```(\w[\w+]*)\s*$")
MARK = re.compile(r"^\s*(?://|#) \[(/?)([\w-]+)\]\s*$")
CODE_LANGUAGES = {"cpp", "c++", "python", "py"}


def fenced_blocks(path):
    """(language, text) of every fenced code block of a Markdown file."""
    blocks, lang, lines = [], None, []
    for line in open(path, encoding="utf-8").read().splitlines():
        if lang is None:
            m = FENCE.match(line)
            if m:
                lang, lines = m.group(1), []
        elif line.startswith("```"):
            blocks.append((lang, "\n".join(lines)))
            lang = None
        else:
            lines.append(line)
    return blocks


def example_snippets():
    """The marked regions of every example, by (file, name): the regions of
    one name joined in order, each dedented, a blank line between."""
    files = glob.glob(os.path.join(REPO, "examples", "**", "*.cpp"), recursive=True) + \
        glob.glob(os.path.join(REPO, "examples", "**", "*.py"), recursive=True)
    snippets = {}
    for path in files:
        regions, current = {}, None
        for line in open(path, encoding="utf-8").read().splitlines():
            m = MARK.match(line)
            if m and not m.group(1):
                current = m.group(2)
                regions.setdefault(current, []).append([])
            elif m:
                current = None
            elif current:
                regions[current][-1].append(line)
        for name, parts in regions.items():
            text = "\n\n".join(textwrap.dedent("\n".join(p)).strip("\n") for p in parts)
            snippets[(os.path.relpath(path, REPO), name)] = text
    return snippets


def documents():
    docs = [os.path.join(REPO, "README.md")]
    docs += [p for p in glob.glob(os.path.join(REPO, "docs", "**", "*.md"), recursive=True)
             if "_generated" not in p]
    return docs


def normalized(text):
    return "\n".join(line.rstrip() for line in text.strip("\n").splitlines())


@pytest.mark.parametrize("path", documents(), ids=lambda p: os.path.relpath(p, REPO))
def test_every_code_block_is_an_examples_region(path):
    snippets = {k: normalized(v) for k, v in example_snippets().items()}
    for lang, text in fenced_blocks(path):
        if lang not in CODE_LANGUAGES:
            continue
        found = [k for k, v in snippets.items() if v == normalized(text)]
        assert found, "%s: a %s block that no example under examples/ holds (mark it there, " \
                      "or include it with literalinclude):\n%s" % (os.path.relpath(path, REPO), lang, text)


def test_literalincludes_name_existing_regions():
    include = re.compile(r"```\{literalinclude\} (\S+)\n(?::[^\n]*\n)*?:start-after: \"([^\"]+)\"")
    for path in documents():
        for target, marker in include.findall(open(path, encoding="utf-8").read()):
            file = os.path.normpath(os.path.join(os.path.dirname(path), target))
            assert os.path.exists(file), "%s includes %s" % (path, target)
            assert marker in open(file, encoding="utf-8").read(), "%s: no %r in %s" % (path, marker, target)


def test_module_docstring_example_runs(monkeypatch):
    monkeypatch.chdir(REPO)  # it reads datasets/radar-paper
    result = doctest.testmod(gssm, verbose=False, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0, result
