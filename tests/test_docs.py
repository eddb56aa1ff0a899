"""Every command block of README.md and docs/*.md runs as written, and every number a document quotes from a
command's output is the one the command prints.

Each ```sh block is run by bash (`set -e -o pipefail`: the first failing command fails the block) in a scratch copy
of the repository (its tracked and new files: no results, no model cache), as a reader following the documents
would. The documents are run as a few chains (:data:`CHAINS`), each a test of its own in a copy of its own, so that
the test run's workers take them side by side: a chain is a list of documents, or of a document's sections (the
blocks under one heading), in reading order (README.md, then the table of contents, docs/README.md), each document's blocks
in order. A page that runs a command on what another page wrote is in that page's chain, after it; a page that
needs what its chain has not yet written fails, as one that needs another chain's output does (its copy has none
of it). `parksteer`, `snakemake` and `python` are this environment's, the package is the copy's (PYTHONPATH),
and the model cache is the checkout's own (results/model, where the rest of the test run builds its models too),
so that a model is compiled, or derived, once in a test run, by whichever test or chain needs it first.

What a document may say about a block, in HTML comments the rendered page does not show, each on a line of its own:

- ``<!-- docs-test: skip (REASON) -->`` before a block: it is not run (the whole pipeline, a SLURM cluster, a
  benchmark of minutes); REASON is required and is listed in the test's output;
- ``<!-- docs-test: skip-line "TEXT" (REASON) -->`` before a block: its commands containing TEXT are left out;
- ``<!-- docs-test: ran-above "TEXT" -->`` before a block: its commands containing TEXT are left out, each being,
  as written, a command an earlier block of its chain ran in the same copy (a page showing again a command it ran
  above: :func:`test_a_command_left_out_as_ran_above_ran_above_in_its_chain`); such a block ties no value to its
  output, which would then lack those commands';
- ``<!-- docs-test: heavy "TEXT" (REASON) -->`` before a block: its commands containing TEXT (a pipeline target or
  a derivation of tens of seconds) run only with PARKSTEER_DOCS_TEST=full in the environment, so that the suite's
  default run stays within its time; the full run is the same test with every such command in;
- ``<!-- docs-test: exits N -->`` before a block: the block's last command must end with status N (a documented
  refusal), not 0;
- ``<!-- docs-test: quotes VALUE from SOURCE: REGEX -->`` after a block: SOURCE (``output``, the block's stdout and
  stderr, or a file the block wrote, relative to the copy) must match REGEX, its first group must be VALUE, and
  VALUE must appear in the document's text outside the markers: a number the prose quotes is the one printed.
- ``<!-- docs-test: appear VALUES in SOURCE -->`` after a block: each of VALUES (space-separated) is a whole number
  of SOURCE (an HTML page's text, its inline figures left out) and appears in the document's text;
- ``<!-- docs-test: given VALUES (REASON) -->`` after a block: numbers the prose after it quotes that are not the
  block's output (an input, a record's hidden truth, a published value, another tool's measurement).

Every number with a decimal point or an exponent in the prose after a block that runs (to the next block or heading)
must be tied by a quotes or appear marker, declared given, or be in the block's commands
(:func:`untied_numbers`). A quotes or appear marker whose source only a heavy line writes is checked in the full
run.

The marker checks are quick; running the blocks (one test a chain, one copy each) and regenerating data/samples/ are
marked slow.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
DOCUMENTS = ["README.md", *sorted(str(p.relative_to(REPO)) for p in (REPO / "docs").glob("*.md"))]
BLOCK_TIMEOUT_S = 600

FENCE = re.compile(r"^```(\w*)\n(.*?)^```\n", re.S | re.M)
MARKER = re.compile(r"^<!--\s*docs-test:\s*(.*?)\s*-->", re.S | re.M)  # on a line of its own
SKIP = re.compile(r"skip\s+\((.+)\)$", re.S)
SKIP_LINE = re.compile(r'skip-line\s+"([^"]+)"\s+\((.+)\)$', re.S)
HEAVY = re.compile(r'heavy\s+"([^"]+)"\s+\((.+)\)$', re.S)
RAN_ABOVE = re.compile(r'ran-above\s+"([^"]+)"$')
FULL = os.environ.get("PARKSTEER_DOCS_TEST") == "full"
EXITS = re.compile(r"exits\s+(\d+)$")
QUOTES = re.compile(r"quotes\s+(\S+)\s+from\s+(\S+?):\s+(.+)$", re.S)
APPEAR = re.compile(r"appear\s+(.+?)\s+in\s+(\S+)$", re.S)
GIVEN = re.compile(r"given\s+(.+?)\s+\((.+)\)$", re.S)
# A number as a command prints it: a decimal point or an exponent (counts, years and percentages are left out).
NUMBER = re.compile(r"(?<![\w.])-?\d+\.\d+(?:e[+-]?\d+)?(?![\w.]*\d)|(?<![\w.])\d+(?:\.\d+)?e[+-]?\d+(?!\w)")


@dataclass
class Block:
    document: str
    line: int
    text: str
    skip: str | None = None
    skip_lines: list[tuple[str, str]] = field(default_factory=list)
    ran_above: list[str] = field(default_factory=list)  # TEXT of each ran-above marker
    exits: int = 0
    quotes: list[tuple[str, str, str]] = field(default_factory=list)
    appears: list[tuple[tuple[str, ...], str]] = field(default_factory=list)  # (values, source)
    given: list[str] = field(default_factory=list)  # values the prose quotes that are not the block's output
    after: str = ""  # the prose after the block, to the next block or heading (markers removed)
    heavy_left_out: bool = False  # lines of a heavy marker left out (PARKSTEER_DOCS_TEST not full)

    def all_commands(self) -> list[str]:
        """Every command of the block (continuation lines joined)."""
        out, current = [], ""
        for line in self.text.splitlines():
            current += line + "\n"
            if not line.endswith("\\"):
                out.append(current)
                current = ""
        if current:
            out.append(current)
        return out

    def commands(self) -> list[str]:
        """The block's commands that run: those a skip-line (or left-out heavy) or ran-above marker names left out."""
        return [c for c in self.all_commands() if not any(text in c for text, _ in self.skip_lines)
                and not any(text in c for text in self.ran_above)]

    def ran_above_commands(self) -> list[str]:
        """The block's commands a ran-above marker names (each must have run earlier in the block's chain)."""
        return [c for c in self.all_commands() if any(text in c for text in self.ran_above)]


def parse(document: str, text: str) -> list[Block]:
    """The ```sh blocks of `text` with their markers; a malformed or misplaced marker is an error."""
    blocks: list[Block] = []
    position = 0
    pending: list[str] = []
    fences = list(FENCE.finditer(text))
    markers = [(m.start(), m.group(1)) for m in MARKER.finditer(text)]
    events = sorted([(m.start(), "fence", m) for m in fences] + [(start, "marker", body) for start, body in markers],
                    key=lambda e: e[0])
    last: Block | None = None
    for start, kind, item in events:
        line = text.count("\n", 0, start) + 1
        if kind == "marker":
            body = item
            if QUOTES.match(body) or APPEAR.match(body) or GIVEN.match(body):
                if last is None:
                    raise AssertionError(f"{document}:{line}: a quotes, appear or given marker before any block")
                if QUOTES.match(body):
                    last.quotes.append(QUOTES.match(body).groups())
                elif APPEAR.match(body):
                    values, source = APPEAR.match(body).groups()
                    last.appears.append((tuple(values.split()), source))
                else:
                    last.given += GIVEN.match(body).group(1).replace(",", " ").split()
            elif (SKIP.match(body) or SKIP_LINE.match(body) or HEAVY.match(body) or EXITS.match(body)
                  or RAN_ABOVE.match(body)):
                pending.append(body)
            else:
                raise AssertionError(f"{document}:{line}: unknown docs-test marker {body!r} (skip (REASON), "
                                     "skip-line \"TEXT\" (REASON), heavy \"TEXT\" (REASON), ran-above \"TEXT\", "
                                     "exits N, quotes VALUE from SOURCE: REGEX, appear VALUES in SOURCE, "
                                     "given VALUES (REASON))")
            continue
        language, body = item.group(1), item.group(2)
        if language != "sh":
            if pending:
                raise AssertionError(f"{document}:{line}: docs-test marker before a ```{language} block")
            last = None
            continue
        block = Block(document, line, body)
        rest = text[item.end():]
        stop = re.search(r"^(```|#)", rest, re.M)
        block.after = prose(rest[:stop.start() if stop else len(rest)])
        for marker in pending:
            if (m := SKIP.match(marker)) is not None:
                block.skip = m.group(1)
            elif (m := SKIP_LINE.match(marker)) is not None:
                block.skip_lines.append((m.group(1), m.group(2)))
            elif (m := RAN_ABOVE.match(marker)) is not None:
                block.ran_above.append(m.group(1))
            elif (m := HEAVY.match(marker)) is not None:
                if not FULL:
                    block.skip_lines.append((m.group(1), f"heavy, run with PARKSTEER_DOCS_TEST=full: {m.group(2)}"))
                    block.heavy_left_out = True
            else:
                block.exits = int(EXITS.match(marker).group(1))
        pending = []
        blocks.append(block)
        last = block
    if pending:
        raise AssertionError(f"{document}: docs-test marker {pending[0]!r} after the last block")
    return blocks


def prose(text: str) -> str:
    """The document without its markers (where a quoted value must appear)."""
    return MARKER.sub("", text)


def documents() -> dict[str, str]:
    return {name: (REPO / name).read_text(encoding="utf-8") for name in DOCUMENTS}


def check_quote(block: Block, doc_prose: str, value: str, source: str, regex: str, work: Path, output: str) -> str | None:
    """None if the quote holds, else what is wrong (one line)."""
    where = f"{block.document}:{block.line}"
    if value not in doc_prose:
        return f"{where}: quoted value {value!r} does not appear in the document's text"
    if source == "output":
        subject = output
    else:
        path = work / source
        if not path.is_file():
            return f"{where}: quoted source {source} was not written by the block"
        subject = path.read_text(encoding="utf-8", errors="replace")
    found = re.search(regex, subject)
    if found is None:
        return f"{where}: {source} does not match {regex!r}"
    if found.group(1) != value:
        return f"{where}: the document quotes {value!r}, {source} gives {found.group(1)!r} ({regex!r})"
    return None


def check_appear(block: Block, doc_prose: str, values: tuple[str, ...], source: str, work: Path,
                 output: str) -> list[str]:
    """What is wrong with an appear marker (one line each): each value must be in the document's text and be a
    number of SOURCE (``output`` or a file the block wrote), whole (0.05 is not found in 0.051)."""
    where = f"{block.document}:{block.line}"
    if source == "output":
        subject = output
    else:
        path = work / source
        if not path.is_file():
            return [f"{where}: source {source} was not written by the block"]
        subject = path.read_text(encoding="utf-8", errors="replace")
        if path.suffix == ".html":  # the page's text, not the coordinates of its inline figures
            subject = re.sub(r"<svg\b.*?</svg>", "", subject, flags=re.S)
    problems = []
    for value in values:
        if value not in doc_prose:
            problems.append(f"{where}: value {value!r} does not appear in the document's text")
        elif not re.search(rf"(?<![\w.]){re.escape(value)}(?![\w]|\.\d)", subject):
            problems.append(f"{where}: the document quotes {value!r}, which {source} does not print")
    return problems


def untied_numbers(block: Block) -> list[str]:
    """The numbers the prose after a block quotes (:data:`NUMBER`) that no marker ties to its output (quotes,
    appear) or declares given, and that its commands do not hold."""
    tied = {v for v, _, _ in block.quotes} | {v for values, _ in block.appears for v in values} | set(block.given)
    return [n for n in NUMBER.findall(block.after) if n not in tied and n not in block.text]


# --- the markers: quick --------------------------------------------------------------------------------------------

def test_markers_parse_and_every_skip_has_a_reason():
    """Every document's markers parse, every sh block is either run or skipped with a non-empty reason, and every
    quoted value appears in its document's text: a marker that names a value the prose no longer quotes fails."""
    total = skipped = 0
    for name, text in documents().items():
        blocks = parse(name, text)
        for block in blocks:
            total += 1
            if block.skip is not None:
                skipped += 1
                assert block.skip.strip(), f"{name}:{block.line}: skip without a reason"
            for _, reason in block.skip_lines:
                assert reason.strip(), f"{name}:{block.line}: skip-line without a reason"
            for value, _, regex in block.quotes:
                assert value in prose(text), f"{name}:{block.line}: quoted {value!r} is not in the text"
                assert re.compile(regex).groups >= 1, f"{name}:{block.line}: quote regex {regex!r} has no group"
    assert total >= 20 and skipped < total  # the parser found the blocks; most run


def test_every_number_after_a_run_block_is_tied_or_given():
    """Each number the prose after a block that runs quotes (to the next block or heading) is tied to what the block
    prints or writes (a quotes or appear marker, checked when the block runs), or declared given with a reason (an
    input, a record's hidden truth, a published value), or is in the block's commands: a number cannot drift
    unseen."""
    problems = []
    for name, text in documents().items():
        for block in parse(name, text):
            if block.skip is None and (untied := untied_numbers(block)):
                problems.append(f"{name}:{block.line}: {', '.join(dict.fromkeys(untied))}")
    assert not problems, "numbers neither tied nor given:\n" + "\n".join(problems)


def test_marker_checks_can_fail(tmp_path):
    """The quote check refuses a number the command does not print, a value missing from the prose and a source the
    block did not write; an unknown marker is refused."""
    block = Block("doc.md", 1, "true\n")
    assert check_quote(block, "the floor is 0.051 N m", "0.051", "output", r"floor ([0-9.]+)", tmp_path,
                       "floor 0.051") is None
    assert "gives '0.052'" in check_quote(block, "the floor is 0.051 N m", "0.051", "output", r"floor ([0-9.]+)",
                                          tmp_path, "floor 0.052")
    assert "does not appear" in check_quote(block, "no number here", "0.051", "output", r"floor ([0-9.]+)",
                                            tmp_path, "floor 0.051")
    assert "was not written" in check_quote(block, "0.051", "0.051", "report.md", r"([0-9.]+)", tmp_path, "")
    assert check_appear(block, "0.05 and 0.12", ("0.05", "0.12"), "output", tmp_path, "0.05 N m, 0.12 N m") == []
    assert "does not print" in check_appear(block, "0.05", ("0.05",), "output", tmp_path, "0.051 N m")[0]
    marked = parse("doc.md", "```sh\necho 1.5\n```\n<!-- docs-test: given 0.75 (an input) -->\n\n"
                             "It prints 1.5 from 0.75 and 2.25.\n")[0]
    assert untied_numbers(marked) == ["2.25"]
    with pytest.raises(AssertionError, match="unknown docs-test marker"):
        parse("doc.md", "<!-- docs-test: skipp (typo) -->\n```sh\ntrue\n```\n")
    blocks = parse("doc.md", '<!-- docs-test: skip-line "pip" (installing) -->\n```sh\npip install x\nls \\\n  -l\n```\n')
    assert blocks[0].commands() == ["ls \\\n  -l\n"]


# --- running the blocks: slow --------------------------------------------------------------------------------------

@pytest.fixture(scope="session")
def model_cache():
    """The checkout's model cache (results/model, the package's own cache when it runs from the checkout), shared by
    every chain and every other test of the run, in whichever worker process: an entry is built aside and renamed
    into place under a build lock (parksteer.model.codegen.cache), so two processes needing one model build it
    once. A copied or per-process cache would compile the same models again in each worker and each copy."""
    cache = REPO / "results" / "model"
    cache.mkdir(parents=True, exist_ok=True)
    return cache


def run_block(block: Block, work: Path, env: dict) -> tuple[int, str, float]:
    script = "".join(block.commands())
    prefix = "set -o pipefail\n" if block.exits else "set -e -o pipefail\n"
    start = time.perf_counter()
    done = subprocess.run(["bash", "-c", prefix + script], cwd=work, env=env, capture_output=True, text=True,
                          timeout=BLOCK_TIMEOUT_S)
    return done.returncode, done.stdout + done.stderr, time.perf_counter() - start


CONTENTS = "docs/README.md"  # the table of contents: the pages in reading order


def readme_order() -> list[str]:
    """README.md, then the table of contents (docs/README.md) and the pages it links, in its order (a reader's)."""
    text = (REPO / CONTENTS).read_text(encoding="utf-8")
    linked = list(dict.fromkeys(re.findall(r"^\d+\. \[[^]]+\]\(([\w.-]+\.md)\)", text, re.M)))
    return ["README.md", CONTENTS, *(f"docs/{name}" for name in linked)]


# The chains the documents run as (module docstring), each in reading order; an entry is a document (all its blocks)
# or "DOCUMENT#HEADING" (the blocks whose nearest heading above starts with HEADING). The blocks of one chain do not
# read what another chain's write: each section of README.md under "Use it" is a reader's errand of its own, and the
# pages each build on their own commands' outputs; a page goes in the chain of the page whose outputs or derived
# models it uses again (docs/targets.md's fig3 is README.md's). Split so that no chain alone takes longer than the others together take on a second worker, and
# listed longest first (the order the test run's workers start them in: tests/conftest.py).
CHAINS: dict[str, list[str]] = {
    "buses_and_vehicles": ["docs/bus.md", "docs/vehicles.md", "docs/assist.md", "docs/assist_sizing.md"],
    "figures_and_models": ["README.md#What it builds", "docs/targets.md", "docs/model.md", "docs/reproducibility.md",
                           "docs/workflow.md", "docs/sweeps.md", "docs/scaling.md", "docs/measurement.md",
                           "docs/diagnosis.md", "docs/peers.md", "docs/house.md", "docs/development.md"],
    "missing_effect": ["docs/signature.md"],
    "use_it": ["README.md#Quick start", "README.md#Use it", "README.md#A worked example", "docs/assist_identify.md"],
    "assisted_car": ["docs/assist_diagnosis.md"],
}


def headings(text: str) -> list[tuple[int, str]]:
    """(line, heading text) of each Markdown heading of `text`, those inside fenced blocks left out."""
    out, fenced = [], False
    for number, line in enumerate(text.splitlines(), start=1):
        if line.startswith("```"):
            fenced = not fenced
        elif not fenced and (m := re.match(r"#+\s+(.*)", line)):
            out.append((number, m.group(1).strip()))
    return out


def section_of(block: Block, marks: list[tuple[int, str]]) -> str:
    """The text of the nearest heading above `block` ("" before the first)."""
    above = [title for line, title in marks if line < block.line]
    return above[-1] if above else ""


def chain_blocks(chain: list[str]) -> list[tuple[str, list[Block]]]:
    """(document, its blocks the chain runs) for each entry of `chain`, in the chain's order."""
    out = []
    for entry in chain:
        document, _, heading = entry.partition("#")
        text = (REPO / document).read_text(encoding="utf-8")
        blocks, marks = parse(document, text), headings(text)
        out.append((document, [b for b in blocks if not heading or section_of(b, marks).startswith(heading)]))
    return out


def test_chains_run_every_block_once_in_readme_order():
    """Every block of every document is in exactly one chain (a section entry names a heading that is there), and
    each chain keeps README order: its documents in reading order (the table of contents), each document's blocks
    in the document's order. A block left out of the chains, or run twice, fails."""
    order = readme_order()
    seen: dict[tuple[str, int], str] = {}
    for name, chain in CHAINS.items():
        position = []
        for (document, blocks), entry in zip(chain_blocks(chain), chain):
            if "#" in entry:
                heading = entry.partition("#")[2]
                assert any(title.startswith(heading) for _, title in headings((REPO / document).read_text(
                    encoding="utf-8"))), f"{name}: {entry}: no such heading"
            for block in blocks:
                key = (document, block.line)
                assert key not in seen, f"{document}:{block.line} is in chains {seen[key]} and {name}"
                seen[key] = name
                position.append((order.index(document), block.line))
        assert position == sorted(position), f"chain {name} is not in README order"
    every = {(name, b.line) for name, text in documents().items() for b in parse(name, text)}
    assert every - set(seen) == set(), f"blocks in no chain: {sorted(every - set(seen))}"


def ran_above_problems(blocks: list[Block]) -> list[str]:
    """What is wrong with the ran-above markers of `blocks` (one chain's blocks, in its order), one line each: each
    marker names a command of its block, each command it names is, as written, one an earlier block of the chain
    ran (not skipped), and the block ties no value to its output."""
    ran: set[str] = set()
    problems = []
    for block in blocks:
        where = f"{block.document}:{block.line}"
        if block.ran_above:
            named = block.ran_above_commands()
            if block.skip is not None:
                problems.append(f"{where}: a ran-above marker on a skipped block")
            for text in block.ran_above:
                if not any(text in command for command in named):
                    problems.append(f"{where}: ran-above {text!r} names no command of the block")
            for command in named:
                if command not in ran:
                    problems.append(f"{where}: {command.strip()!r} did not run earlier in its chain")
            if any(source == "output" for _, source, _ in block.quotes) or any(
                    source == "output" for _, source in block.appears):
                problems.append(f"{where}: ties a value to its output, which lacks the commands left out as ran above")
        if block.skip is None:
            ran.update(block.commands())
    return problems


def test_a_command_left_out_as_ran_above_ran_above_in_its_chain():
    """A command a ran-above marker leaves out ran, as written, in an earlier block of the same chain (the same
    copy of the repository), so every command of every document still runs once in its chain; a marker naming a
    command that ran nowhere above, or in another chain only, fails (checked on a made-up chain too)."""
    problems = [p for chain in CHAINS.values() for p in ran_above_problems(
        [block for _, blocks in chain_blocks(chain) for block in blocks])]
    assert not problems, "\n".join(problems)
    first = parse("doc.md", "```sh\nparksteer effects\nls\n```\n")
    again = parse("doc.md", '<!-- docs-test: ran-above "effects" -->\n```sh\nparksteer effects\npwd\n```\n')
    assert again[0].commands() == ["pwd\n"] and again[0].ran_above_commands() == ["parksteer effects\n"]
    assert ran_above_problems(first + again) == []
    assert "did not run earlier" in ran_above_problems(again + first)[0]
    tied = parse("doc.md", '<!-- docs-test: ran-above "effects" -->\n```sh\nparksteer effects\n```\n'
                           "<!-- docs-test: quotes 1.5 from output: (1.5) -->\n\nIt prints 1.5.\n")
    assert "ties a value to its output" in ran_above_problems(first + tied)[0]


def test_every_document_in_readme_order():
    """A new document is run: each of README.md and docs/*.md is README.md, the table of contents or one of its
    numbered entries, whose order the documents run in."""
    order = readme_order()
    assert len(order) == len(set(order)), "a page is listed twice in the table of contents"
    assert sorted(order) == sorted(DOCUMENTS), "pages missing from docs/README.md's table of contents: " + ", ".join(
        sorted(set(DOCUMENTS) - set(order)))


@pytest.mark.slow
@pytest.mark.parametrize("chain", list(CHAINS))
def test_documents_run_in_readme_order(chain, tmp_path, copy_repository, model_cache):
    """Every block of the chain's documents runs in one scratch copy, the documents in README order, as one reader
    following them would: a file one page writes is there for the next page of its chain, so a page that needs what
    its chain has not yet written (or what only another chain writes) fails here."""
    work = copy_repository(tmp_path / "repo")
    failures, report = [], []
    for document, blocks in chain_blocks(CHAINS[chain]):
        found, lines = run_document(document, work, model_cache, blocks)
        failures += found
        report += lines
    print("\n".join(report))
    assert not failures, "\n\n".join(failures)


@pytest.mark.slow
def test_samples_are_their_generator_s(tmp_path):
    """data/samples/ holds what `python data/samples/make_samples.py` writes, byte for byte."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("make_samples", REPO / "data" / "samples" / "make_samples.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    written = module.write_samples(tmp_path)
    shipped = sorted(p.relative_to(REPO / "data" / "samples") for p in (REPO / "data" / "samples").rglob("*")
                     if p.is_file() and p.suffix not in (".md", ".py"))
    assert sorted(p.relative_to(tmp_path) for p in written) == shipped
    for name in shipped:
        assert (tmp_path / name).read_bytes() == (REPO / "data" / "samples" / name).read_bytes(), name


def run_document(document: str, work: Path, model_cache: Path, blocks: list[Block] | None = None
                 ) -> tuple[list[str], list[str]]:
    """Each sh block of `document` (or those of `blocks`, its blocks a chain runs) runs in the scratch copy `work`,
    in order, and ends with status 0 (or the status its exits marker states); each quote marker's value is what the
    block printed or wrote. Returns the failures and the lines of what ran (skipped blocks and lines with their
    reasons)."""
    text = (REPO / document).read_text(encoding="utf-8")
    blocks = parse(document, text) if blocks is None else blocks
    bin_dir = str(Path(sys.executable).parent)
    env = dict(os.environ, PYTHONPATH=str(work / "src"), PARKSTEER_MODEL_CACHE=str(model_cache),
               PATH=bin_dir + os.pathsep + os.environ.get("PATH", ""))
    env.pop("VIRTUAL_ENV", None)
    failures, report = [], []
    for block in blocks:
        if block.skip is not None:
            report.append(f"{document}:{block.line}: skipped ({block.skip})")
            continue
        for text_, reason in block.skip_lines:
            report.append(f"{document}:{block.line}: lines with {text_!r} skipped ({reason})")
        for text_ in block.ran_above:
            report.append(f"{document}:{block.line}: lines with {text_!r} ran above in this copy")
        status, output, seconds = run_block(block, work, env)
        report.append(f"{document}:{block.line}: ran in {seconds:.1f} s, status {status}")
        if status != block.exits:
            tail = "\n".join(output.strip().splitlines()[-15:])
            failures.append(f"{document}:{block.line}: status {status} (expected {block.exits}):\n{tail}")
            continue
        for value, source, regex in block.quotes:
            if heavy_source(block, source, work):
                report.append(f"{document}:{block.line}: {value!r} from {source} not checked (written by a heavy line)")
                continue
            problem = check_quote(block, prose(text), value, source, regex, work, output)
            if problem is not None:
                failures.append(problem)
        for values, source in block.appears:
            if heavy_source(block, source, work):
                report.append(f"{document}:{block.line}: {' '.join(values)} from {source} not checked (written by a "
                              "heavy line)")
                continue
            failures += check_appear(block, prose(text), values, source, work, output)
    return failures, report


def heavy_source(block: Block, source: str, work: Path) -> bool:
    """Whether `source` is a file only a heavy line the run left out writes: not there, and named in such a line."""
    if not block.heavy_left_out or source == "output" or (work / source).exists():
        return False
    return any(source in command for command in block.text.splitlines()
               if any(text in command for text, reason in block.skip_lines if reason.startswith("heavy")))
