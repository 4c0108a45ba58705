"""doc/solver.md's option table is the table `femcod run --help` prints from the parser's
one option table (src/cli/femcod_run_options.f90 and the scene options): every option the
parser takes has a row there, and the doc names no option the parser lacks. A new option
of `femcod run` fails this test until its row is written.
"""
import os
import re

from conftest import REPO, run_femcod

OPTION = re.compile(r"--[a-z][a-z0-9-]*")


def help_options():
    """The options `femcod run --help` lists, one per line: '  --name ...' or '  -o, --name ...'."""
    text = run_femcod("run", "--help").stdout
    names = set()
    for line in text.splitlines():
        m = re.match(r"^  (?:-[a-z], )?(--[a-z][a-z0-9-]*)", line)
        if m:
            names.add(m.group(1))
    return names


def doc_table_options():
    """Every --name in the rows of doc/solver.md's '## Options' table."""
    text = open(os.path.join(REPO, "doc", "solver.md"), encoding="utf-8").read()
    section = text[text.index("\n## Options"):]
    rows = []
    for line in section.splitlines()[1:]:
        if line.startswith("|"):
            rows.append(line)
        elif rows:
            break
    return set(OPTION.findall("\n".join(rows)))


def test_doc_table_names_every_run_option():
    listed, documented = help_options(), doc_table_options()
    assert len(listed) > 30, sorted(listed)
    assert not listed - documented, f"options without a row in doc/solver.md: {sorted(listed - documented)}"


def test_doc_table_names_no_unknown_option():
    listed, documented = help_options(), doc_table_options()
    assert not documented - listed, f"doc/solver.md names options femcod run lacks: {sorted(documented - listed)}"


def test_library_keywords_are_the_option_table():
    """femcod.solve's keywords for run's options come from the library's option table
    (femcod_option_names): every one is an option femcod run --help lists, and the table's
    newest, --tangential-tol, is among them."""
    import femcod
    keywords = femcod.option_keywords()
    listed = help_options()
    assert "tangential_tol" in keywords and "tol" in keywords, keywords
    assert all("--" + k.replace("_", "-") in listed for k in keywords), keywords
    assert not {"solver", "loads", "approach", "plastic", "adhesion"} & set(keywords), keywords
