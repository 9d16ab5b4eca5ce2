"""What a user reads is true, stands alone and runs: README.md and docs/*.md.

- No page points outside the project (`../shared/`, `shared/`): users have only the project.
- Every `avsim` command line in a fenced ```bash block runs, as written but shortened the
  same way for all (`shorten`): a `run` gets `--set duration=2` (last given wins) and, when
  it names no profile, the lightest profile its scenario accepts (`none`, or `fast` where
  the route has traffic lights for the camera to read); a `suite`, `sweep` or `campaign`
  runs with `--dry-run` (every run loaded and checked, none run), and the first run it
  prints is then run for real, shortened as a `run` (the profile it names is the batch's
  default, not the page's, so it goes too unless the page named one). A command already run
  as the same words (pages repeat a few) is not run again. `view` needs a display: it is
  checked up to there, by its `--help` and by the recording the page names being one an
  earlier command wrote (or `make demo` writes). Commands run in a fresh folder that links
  the project's `scenarios/`, `docs/`, `tests/` and `examples/` (so the pages' relative
  paths hold) and takes every output, through the command's entry point in this process
  (click's runner, `tests.avsim.invoke`: an interpreter start and avsim's imports cost
  about 2 s a command, most of a shortened run; the exit status, output and files are what
  is judged); an exception that is not an exit fails the test as a traceback would.
- A command in any other fenced block is an error: a page cannot hide one from this test.
- The minimal OpenSCENARIO example runs in full and passes, as a real process.
"""

from __future__ import annotations

import glob
import json
import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from avsim.scenario.errors import ScenarioError
from avsim.scenario.load import load_scenario
from avsim.scenario.profile_fit import CAMERALESS, check_profile
from tests.avsim.invoke import invoke

REPO = Path(__file__).resolve().parents[1]
PAGES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
LINKED = ("scenarios", "docs", "tests", "examples")  # the project folders the pages' paths
#   point into
AVSIM = (".venv/bin/avsim", "avsim")  # how a page spells the command
RUN_EXIT = (0, 1)  # a shortened run may fail a criterion it had no time to meet
TIMEOUT = 600.0  # [s] per command: a paper-profile run of 2 s stays far below it
FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.MULTILINE | re.DOTALL)


@dataclass(frozen=True)
class Command:
    page: str  # the page's name, for messages
    words: tuple[str, ...]  # after `avsim`, comments and continuation lines resolved
    stdout_to: str | None  # a `> FILE` redirection


def _blocks(page: Path) -> list[tuple[str, str]]:
    """(language, text) of every fenced block of `page`."""
    return [(m.group(1), m.group(2)) for m in FENCE.finditer(page.read_text(encoding="utf-8"))]


def _lines(text: str) -> list[str]:
    """The block's logical lines: backslash continuations joined, a leading `$ ` dropped."""
    joined = text.replace("\\\n", " ")
    return [line.strip().removeprefix("$ ") for line in joined.splitlines() if line.strip()]


def _is_command(line: str) -> bool:
    return line.split(" ", 1)[0] in AVSIM


def commands() -> list[Command]:
    """Every `avsim` command of the pages' bash blocks, in page order."""
    found: list[Command] = []
    for page in PAGES:
        for language, text in _blocks(page):
            if language != "bash":
                continue
            for line in filter(_is_command, _lines(text)):
                words = shlex.split(line, comments=True)[1:]
                redirect = words.index(">") if ">" in words else None
                to = None if redirect is None else words[redirect + 1]
                words = words if redirect is None else words[:redirect] + words[redirect + 2:]
                found.append(Command(page.name, tuple(words), to))
    return found


def test_no_page_points_outside_the_project() -> None:
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        assert "../shared" not in text and "shared/" not in text, page.name


def test_every_command_is_in_a_bash_block() -> None:
    for page in PAGES:
        for language, text in _blocks(page):
            hidden = [line for line in _lines(text) if _is_command(line)]
            assert language == "bash" or not hidden, (page.name, hidden)
    assert len(commands()) >= 20  # the README's and the docs' examples are all found


def test_the_pages_show_the_bundled_openscenario_examples() -> None:
    words = [c.words for c in commands()]
    assert ("run", "alks/4_4_1_cut_in_no_collision", "--criteria", "r157") in words
    assert any("docs/examples/minimal.xosc" in w for w in words)


@pytest.fixture(scope="module")
def workdir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A fresh folder with the project's scenario and docs folders linked in."""
    path = tmp_path_factory.mktemp("docs_commands")
    for name in LINKED:
        (path / name).symlink_to(REPO / name)
    return path


def _avsim(words: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    return subprocess.run([sys.executable, "-m", "avsim.cli", *words], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=TIMEOUT, check=False)


def _lightest_profile(scenario: str, cwd: Path) -> str:
    """`none` when the scenario accepts it, else `fast` (module doc)."""
    path = cwd / scenario
    try:
        loaded = load_scenario(path if path.exists() else scenario)
    except ScenarioError:
        return CAMERALESS  # the run reports its own load error
    try:
        check_profile(loaded, CAMERALESS, scenario)
    except ScenarioError:
        return "fast"
    return CAMERALESS


def shorten(words: list[str], cwd: Path) -> list[str]:
    """A run, shortened (module doc): 2 s simulated, the lightest profile its scenario
    accepts unless it names one."""
    profile = [] if "--profile" in words else ["--profile", _lightest_profile(words[1], cwd)]
    return [*words, "--set", "duration=2", *profile, "--no-progress"]


def _without_profile(words: list[str]) -> list[str]:
    """`words` without their `--profile X`."""
    if "--profile" not in words:
        return words
    at = words.index("--profile")
    return words[:at] + words[at + 2:]


def _expand(words: tuple[str, ...], cwd: Path) -> list[str]:
    """Shell globs expanded in `cwd`, as bash would."""
    out: list[str] = []
    for word in words:
        matches = sorted(glob.glob(word, root_dir=cwd)) if any(c in word for c in "*?[") else []
        out += matches or [word]
    return out


def _check(command: Command, cwd: Path, done_before: set[tuple[str, ...]]) -> None:
    words = _expand(command.words, cwd)
    what = f"{command.page}: avsim {' '.join(command.words)}"
    if words[0] == "view":  # needs a display: checked up to it (module doc)
        done = invoke("view", "--help", cwd=cwd)
        assert done.returncode == 0, (what, done.stderr)
        recording = next(w for w in words[1:] if not w.startswith("-"))
        assert (cwd / recording).is_file(), (what, "no earlier command wrote it")
        return
    if words[0] in ("suite", "sweep", "campaign"):
        done = invoke(*words, "--dry-run", cwd=cwd)
        assert done.returncode == 0, (what, done.stderr)
        planned = done.stdout.splitlines()
        assert planned and all(line.startswith("avsim run ") for line in planned), what
        words = shlex.split(planned[0])[1:]
        if "--profile" not in command.words:
            words = _without_profile(words)
    if words[0] == "run":
        words = shorten(words, cwd)
    if (*words, str(command.stdout_to)) in done_before:
        return
    done_before.add((*words, str(command.stdout_to)))
    done = invoke(*words, cwd=cwd)
    allowed = RUN_EXIT if words[0] == "run" else (0,)
    assert done.returncode in allowed, (what, words, done.returncode, done.stderr[-2000:])
    assert "Traceback" not in done.stderr, (what, done.stderr[-2000:])
    if command.stdout_to is not None:
        (cwd / command.stdout_to).write_text(done.stdout, encoding="utf-8")


@pytest.mark.slow
def test_every_command_of_the_pages_runs(workdir: Path) -> None:
    done_before: set[tuple[str, ...]] = set()
    for command in commands():
        _check(command, workdir, done_before)
    schema = workdir / "scenario.schema.json"
    assert json.loads(schema.read_text(encoding="utf-8"))["$schema"]


@pytest.mark.slow
def test_the_minimal_openscenario_example_runs_and_passes(tmp_path: Path) -> None:
    example = REPO / "docs" / "examples" / "minimal.xosc"
    done = _avsim(["run", str(example), "--profile", "fast", "--out", "m.rrd", "--no-progress"],
                  tmp_path)
    assert done.returncode == 0, done.stderr
    result = json.loads((tmp_path / "m.json").read_text(encoding="utf-8"))
    story = {entry["element"]: entry["fired_at"] for entry in result["story"]}
    assert story["BrakeAction"] == pytest.approx(8.0, abs=0.05)
    # the lead stands 50 / 3.6 / 4 = 3.47 s later; the StopTrigger fires 5 s after that
    assert story["StopTrigger"] == pytest.approx(8.0 + 50 / 3.6 / 4 + 5.0, abs=0.1)
    assert result["passed"] and result["metrics"]["collisions"] == 0
