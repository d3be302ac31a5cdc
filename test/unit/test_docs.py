"""The README stays a newcomer's page, and the manual in docs/ stays true to the tree.

A README grows back into a manual unless something keeps it short, and a page that moved
leaves links and command lines pointing at nothing. Checked here, on README.md and docs/*.md:
the README's length; every relative link (and image) resolves to a file, and a `#anchor` to a
heading of that file (GitHub's slugs); every program a ```sh block runs from this package
(`scripts/X`, `tools/X`, `rosrun tutorial_atlas_control X`, `roslaunch tutorial_atlas_control
X.launch`, `make X`) exists; and no page cites the tracker's issue numbers, which are not in
the repository. The checks run on synthetic trees too, so that each is seen to fail.
"""

from __future__ import annotations

import re
import unicodedata
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PACKAGE = 'tutorial_atlas_control'
#: A newcomer reads this much; the manual lives in docs/.
README_MAX_LINES = 150

FENCE = re.compile(r'^(```+|~~~+)\s*(\S*)[^\n]*\n(.*?)^\1\s*$', re.MULTILINE | re.DOTALL)
INLINE_CODE = re.compile(r'`[^`]*`')
LINK = re.compile(r'!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+"[^"]*")?\s*\)')
HEADING = re.compile(r'^#{1,6}[ \t]+(.+?)[ \t]*#*[ \t]*$', re.MULTILINE)
SCHEME = re.compile(r'^[a-zA-Z][a-zA-Z0-9+.-]*:')
SHELL_LANGUAGES = frozenset({'sh', 'bash', 'shell', 'console'})
ROSRUN = re.compile(rf'\brosrun\s+{PACKAGE}\s+(\S+)')
ROSLAUNCH = re.compile(rf'\broslaunch\s+(?:-\S+\s+(?:\d+\s+)?)*{PACKAGE}\s+(\S+)')
REPO_PATH = re.compile(r'(?<![\w/.~-])((?:scripts|tools)/[\w.-]+)')
MAKE = re.compile(r'^\s*make\s+([\w-]+)')
ISSUE_NUMBER = re.compile(r'\bissues \d+(?:, \d+)+|\bissues?[ -]#?\d+', re.IGNORECASE)


def markdown_pages(root: Path) -> list[Path]:
    """README.md and every page under docs/."""
    return [root / 'README.md', *sorted((root / 'docs').glob('*.md'))]


def code_blocks(text: str) -> list[tuple[str, str]]:
    """(language, body) of each fenced code block."""
    return [(match.group(2).lower(), match.group(3)) for match in FENCE.finditer(text)]


def prose(text: str) -> str:
    """The text without code blocks and code spans, where links are links."""
    return INLINE_CODE.sub('', FENCE.sub('', text))


def github_slug(heading: str) -> str:
    """The anchor GitHub gives a heading: its rendered text, lower case, punctuation other
    than '-' and '_' dropped, spaces turned into '-'."""
    text = re.sub(r'!?\[([^\]]*)\]\([^)]*\)', r'\1', heading)
    text = text.replace('`', '').replace('*', '').lower()
    kept = ''.join(c for c in text if c in ' -' or unicodedata.category(c)[0] in 'LMN'
                   or unicodedata.category(c) == 'Pc')
    return kept.replace(' ', '-')


def anchors(text: str) -> set[str]:
    """Every heading's anchor, repeated headings numbered as GitHub numbers them."""
    seen: dict[str, int] = {}
    found = set()
    for match in HEADING.finditer(FENCE.sub('', text)):
        slug = github_slug(match.group(1))
        count = seen.get(slug, 0)
        seen[slug] = count + 1
        found.add(slug if count == 0 else f'{slug}-{count}')
    return found


def broken_links(page: Path) -> list[str]:
    """'PAGE: TARGET (why)' for each relative link of `page` that leads nowhere."""
    problems = []
    for target in LINK.findall(prose(page.read_text())):
        if SCHEME.match(target):
            continue  # http(s), mailto: not checked here
        path_part, _, anchor = target.partition('#')
        linked = (page.parent / path_part).resolve() if path_part else page
        if not linked.exists():
            problems.append(f'{page.name}: {target} (no file {path_part})')
        elif anchor and linked.suffix == '.md' and anchor not in anchors(linked.read_text()):
            problems.append(f'{page.name}: {target} (no heading #{anchor} in {linked.name})')
    return problems


def _executables(root: Path) -> set[str]:
    """The package's compiled programs (CMakeLists.txt's add_executable)."""
    cmake = root / 'CMakeLists.txt'
    text = cmake.read_text() if cmake.exists() else ''
    return set(re.findall(r'add_executable\(\s*(\S+)', text))


def _make_targets(root: Path) -> set[str]:
    makefile = root / 'Makefile'
    text = makefile.read_text() if makefile.exists() else ''
    return set(re.findall(r'^([\w-]+)\s*:', text, re.MULTILINE))


def _missing_in_line(root: Path, line: str) -> list[str]:
    missing = []
    for name in ROSRUN.findall(line):
        if not (root / 'scripts' / name).exists() and name not in _executables(root):
            missing.append(f'rosrun {PACKAGE} {name}')
    for name in ROSLAUNCH.findall(line):
        if not (root / 'launch' / name).exists():
            missing.append(f'roslaunch {PACKAGE} {name}')
    for path in REPO_PATH.findall(line):
        if not (root / path).exists():
            missing.append(path)
    for target in MAKE.findall(line):
        if target not in _make_targets(root):
            missing.append(f'make {target}')
    return missing


def missing_programs(root: Path, page: Path) -> list[str]:
    """'PAGE: PROGRAM' for each program of this package a ```sh block of `page` runs that
    the tree does not hold."""
    problems = []
    for language, body in code_blocks(page.read_text()):
        if language in SHELL_LANGUAGES:
            for line in body.splitlines():
                problems += [f'{page.name}: {name}' for name in _missing_in_line(root, line)]
    return problems


def issue_citations(page: Path) -> list[str]:
    return [f'{page.name}: {match.group(0)!r}'
            for match in ISSUE_NUMBER.finditer(page.read_text())]


# -- the repository's pages ------------------------------------------------------------------

def test_readme_is_a_newcomers_page() -> None:
    lines = (REPO / 'README.md').read_text().splitlines()
    assert len(lines) <= README_MAX_LINES, (
        f'README.md has {len(lines)} lines, at most {README_MAX_LINES}: move the detail to '
        'a page in docs/ and link it')


def test_every_docs_page_is_linked_from_the_readme() -> None:
    linked = {(REPO / target.partition('#')[0]).resolve()
              for target in LINK.findall(prose((REPO / 'README.md').read_text()))}
    unlinked = [page.name for page in markdown_pages(REPO)[1:] if page.resolve() not in linked]
    assert not unlinked, f'pages the README does not link: {unlinked}'


@pytest.mark.parametrize('page', markdown_pages(REPO), ids=lambda page: page.name)
def test_links_resolve(page: Path) -> None:
    assert broken_links(page) == []


@pytest.mark.parametrize('page', markdown_pages(REPO), ids=lambda page: page.name)
def test_command_blocks_name_programs_that_exist(page: Path) -> None:
    assert missing_programs(REPO, page) == []


@pytest.mark.parametrize('page', markdown_pages(REPO), ids=lambda page: page.name)
def test_no_page_cites_issue_numbers(page: Path) -> None:
    assert issue_citations(page) == []


#: Source and build files whose comments and docstrings must not cite the tracker either: the
#: tracker is not in the repository, so "issue 27" tells a reader nothing.
CODE_SUFFIXES = ('.py', '.c', '.cpp', '.sh', '.launch', '.test', '.yaml', '.xml', '.txt')
CODE_DIRS = ('src', 'scripts', 'test', 'bench', 'tools', 'launch', 'config', 'trajectories',
             'msg', 'sim')


def test_no_code_cites_issue_numbers() -> None:
    files = [path for folder in CODE_DIRS for path in sorted((REPO / folder).rglob('*'))
             if path.suffix in CODE_SUFFIXES and path.name != Path(__file__).name]
    files += [REPO / name for name in ('Makefile', 'CMakeLists.txt', 'env.sh')]
    assert len(files) > 100, 'the code was not found'
    cited = [f'{path.relative_to(REPO)}: {match.group(0)!r}' for path in files
             for match in ISSUE_NUMBER.finditer(path.read_text(errors='replace'))]
    assert not cited, 'say what the code does, not which issue asked for it:\n' + '\n'.join(cited)


def test_the_layout_page_names_every_module() -> None:
    """docs/layout.md is where a newcomer finds a module: a new one is named there."""
    layout = (REPO / 'docs' / 'layout.md').read_text()
    package = REPO / 'src' / PACKAGE
    modules = [path for path in sorted(package.rglob('*.py')) if path.name != '__init__.py']
    assert len(modules) > 50, 'the package was not found'
    unnamed = [str(path.relative_to(package)) for path in modules
               if f'`{path.name}`' not in layout
               and f'{path.parent.name}/{path.name}' not in layout]
    assert not unnamed, f'docs/layout.md does not name: {unnamed}'


# -- the checks themselves, on synthetic trees -----------------------------------------------

@pytest.mark.parametrize(('heading', 'slug'), [
    ('Live plots, where DRCSim\'s tutorials typed `rqt_plot`',
     'live-plots-where-drcsims-tutorials-typed-rqt_plot'),
    ('Sweeping many offline runs (Dask)', 'sweeping-many-offline-runs-dask'),
    ('`make bench`: the simulator\'s performance', 'make-bench-the-simulators-performance'),
    ('DRCSim\'s 1 kHz duplicates are not recorded', 'drcsims-1-khz-duplicates-are-not-recorded'),
])
def test_github_slugs(heading: str, slug: str) -> None:
    assert github_slug(heading) == slug


def test_repeated_headings_are_numbered() -> None:
    assert anchors('# A\n\n## Notes\n\n## Notes\n') == {'a', 'notes', 'notes-1'}


def _tree(tmp_path: Path, readme: str, page: str = '# Page\n\n## Part one\n') -> Path:
    (tmp_path / 'docs').mkdir()
    (tmp_path / 'scripts').mkdir()
    (tmp_path / 'scripts' / 'real.py').write_text('')
    (tmp_path / 'CMakeLists.txt').write_text('add_executable(echo_controller src/x.cpp)\n')
    (tmp_path / 'Makefile').write_text('demo: setup\n\t./x\nsetup:\n')
    (tmp_path / 'docs' / 'page.md').write_text(page)
    (tmp_path / 'README.md').write_text(readme)
    return tmp_path


def test_a_link_to_a_missing_file_or_heading_is_found(tmp_path: Path) -> None:
    root = _tree(tmp_path, '# R\n\n[ok](docs/page.md#part-one), [gone](docs/gone.md), '
                           '[wrong](docs/page.md#part-two), [here](#r), [nowhere](#s), '
                           '`[code](not/a/link.md)`, [web](https://example.org/x.md)\n')
    assert broken_links(root / 'README.md') == [
        'README.md: docs/gone.md (no file docs/gone.md)',
        'README.md: docs/page.md#part-two (no heading #part-two in page.md)',
        'README.md: #s (no heading #s in README.md)',
    ]


def test_a_link_across_a_line_break_is_checked(tmp_path: Path) -> None:
    root = _tree(tmp_path, '# R\n\nsee [the\npage](docs/missing.md)\n')
    assert broken_links(root / 'README.md') == [
        'README.md: docs/missing.md (no file docs/missing.md)']


def test_a_command_block_naming_a_missing_program_is_found(tmp_path: Path) -> None:
    root = _tree(tmp_path, '# R\n\n```sh\n'
                           f'rosrun {PACKAGE} real.py X\n'
                           f'rosrun {PACKAGE} echo_controller\n'
                           f'rosrun {PACKAGE} gone.py X   # a comment\n'
                           'python3 scripts/missing.py --help\n'
                           'python3 tools/absent.py\n'
                           f'roslaunch {PACKAGE} nowhere.launch\n'
                           'make demo\n'
                           'make nothing\n'
                           '```\n\n'
                           '```text\nrosrun tutorial_atlas_control not_a_command.py\n```\n')
    assert missing_programs(root, root / 'README.md') == [
        f'README.md: rosrun {PACKAGE} gone.py',
        'README.md: scripts/missing.py',
        'README.md: tools/absent.py',
        f'README.md: roslaunch {PACKAGE} nowhere.launch',
        'README.md: make nothing',
    ]


def test_an_issue_number_is_found(tmp_path: Path) -> None:
    root = _tree(tmp_path, '# R\n\nAs issue 27 asked; the issue-32 session; issues 8, 18.\n'
                           'A tissue 5 cm wide is not one.\n')
    assert issue_citations(root / 'README.md') == [
        "README.md: 'issue 27'", "README.md: 'issue-32'", "README.md: 'issues 8, 18'"]
