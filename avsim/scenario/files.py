"""Finding a scenario file and reading its YAML.

A scenario argument is a file path, or the name of a bundled scenario (`bundled_groups`:
`scenarios/NAME.yaml` is `NAME`, `scenarios/acceptance/NAME.yaml` `acceptance/NAME`, the
vendored `alks_scenario_4_4_1_..._template.xosc` `alks/4_4_1_...`, and so on).
The YAML is read with a strict safe loader: a key written twice in one
mapping is an error (PyYAML would keep the last), plain scalars are read by the YAML 1.2
core schema (``1e9`` is a number, ``yes`` is text) with integers of at most `MAX_INT_DIGITS`
digits. Only a regular file is read, and at most `MAX_FILE_BYTES` of it
(`world.core.safe_read.read_bounded`: `/dev/zero` or a FIFO is refused, not read). Before
the YAML is composed, its parser's events are walked (`avsim.scenario.yaml_events`): a text
nested over `MAX_DEPTH` levels or holding over `MAX_VALUES` values (anchors and merge keys
expanded) is refused there. Problems are `LocatedError`s keyed `(file)` or `line N`.
"""

from __future__ import annotations

import re
from collections.abc import Hashable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import yaml

from avsim.scenario.bounds import MAX_FILE_BYTES, MAX_INT_DIGITS
from avsim.scenario.errors import FILE_KEY, LocatedError, ScenarioError, show
from avsim.scenario.yaml_events import YamlBoundError, check_events
from world.core.safe_read import UnreadableFileError, read_bounded

REPO_ROOT = Path(__file__).resolve().parents[2]  # the repository this package sits in
SCENARIO_DIR = REPO_ROOT / "scenarios"  # the bundled scenarios
ALKS_DIR = REPO_ROOT / "tests/data/alks/logical_scenarios/concrete_scenarios"  # vendored
SCENARIO_SUFFIXES = frozenset({".yaml", ".yml", ".xosc"})  # an argument ending so is a path


@dataclass(frozen=True, slots=True)
class BundledGroup:
    """One folder of bundled scenarios and how its files are named on the command line:
    `prefix` + the file's stem, less `strip`'s leading and trailing parts."""

    folder: Path  # where the files are
    pattern: str  # which files of it are scenarios (a glob)
    prefix: str = ""  # the names' folder part: "" or "<group>/"
    strip: tuple[str, str] = ("", "")  # removed from the stem's start and end
    note: str = ""  # what `avsim list` says of the group besides its folder

    def name_of(self, path: Path) -> str:
        """The bundled name of `path`, one of this group's files."""
        head, tail = self.strip
        return self.prefix + path.stem.removeprefix(head).removesuffix(tail)

    def files(self) -> list[Path]:
        """The group's scenario files, sorted by name."""
        return sorted(self.folder.glob(self.pattern))


def bundled_groups() -> tuple[BundledGroup, ...]:
    """The folders of bundled scenarios, in the order `avsim list` shows them."""
    return (
        BundledGroup(SCENARIO_DIR, "*.yaml"),
        BundledGroup(SCENARIO_DIR / "acceptance", "*.yaml", "acceptance/",
                     note="test protocols; a file's grid runs as a suite or a sweep"),
        BundledGroup(SCENARIO_DIR / "faults", "*.yaml", "faults/", note="sensor faults"),
        BundledGroup(ALKS_DIR, "alks_scenario_*.xosc", "alks/",
                     ("alks_scenario_", "_template"),
                     note="ASAM ALKS OpenSCENARIO files for UN R157 (MPL-2.0); "
                          "add --criteria r157"),
    )


def bundled_scenarios() -> list[Path]:
    """The bundled scenario files a suite runs by default, `<repo>/scenarios/*.yaml`, sorted
    by name (`bundled_names` has every group)."""
    return bundled_groups()[0].files()


def bundled_names() -> dict[str, list[Path]]:
    """Every bundled name (`avsim run NAME`) and the files it names, group by group: one file
    each, unless two files of a group differ only in what the name leaves out."""
    names: dict[str, list[Path]] = {}
    for group in bundled_groups():
        for path in group.files():
            names.setdefault(group.name_of(path), []).append(path)
    return names


def scenario_path(path_or_name: str | Path) -> Path:
    """The file a scenario argument names: a path (a `Path`, or text ending in `.yaml`,
    `.yml` or `.xosc`), else a bundled name (`bundled_names`), else the path it spells (a
    bare name: `scenarios/<name>.yaml`), which may not exist: the loader says so. Raises
    `ScenarioError` for an ambiguous name: two bundled files, or a bundled name that is also
    a file here."""
    if looks_like_path(path_or_name):
        return Path(path_or_name)
    text = str(path_or_name)
    found = bundled_names().get(text)
    if found is None:  # the loader says "no such file or bundled scenario"
        return Path(text) if "/" in text or Path(text).exists() else SCENARIO_DIR / f"{text}.yaml"
    if len(found) > 1:
        raise ScenarioError(text, FILE_KEY, "ambiguous bundled name: "
                            + " and ".join(str(p) for p in found))
    if Path(text).exists():
        raise ScenarioError(text, FILE_KEY, f"ambiguous: a file here and the bundled "
                            f"{found[0]} (write ./{text} for the file)")
    return found[0]


def looks_like_path(path_or_name: str | Path) -> bool:
    """Whether a scenario argument is meant as a path, not a bundled name: a `Path`, or text
    ending in a scenario file's suffix or starting with `./`, `../` or the root."""
    text = str(path_or_name)
    explicit = text.startswith(("./", "../", "/", "~")) or Path(text).is_absolute()
    return (isinstance(path_or_name, Path) or Path(text).suffix in SCENARIO_SUFFIXES
            or explicit)


def shown_name(path_or_name: str | Path, path: Path) -> str:
    """How the file is named in messages: as the user wrote it, or for a bundled name its
    path relative to the working directory when it lies below it."""
    bundled = any(path.is_relative_to(group.folder) for group in bundled_groups())
    if looks_like_path(path_or_name) or not bundled:
        return str(path_or_name)
    try:
        return str(path.relative_to(Path.cwd()))
    except ValueError:
        return str(path)


_MERGE_TAG = "tag:yaml.org,2002:merge"


if TYPE_CHECKING:
    _Base = yaml.SafeLoader
else:  # libyaml's parser where PyYAML has it (its wheels do): 30 times the pure Python one's
    _Base = yaml.CSafeLoader if yaml.__with_libyaml__ else yaml.SafeLoader


class _StrictLoader(_Base):
    """A safe YAML loader that refuses duplicate keys instead of keeping the last one, and
    reads plain scalars by the YAML 1.2 core schema (`_core_schema`) instead of PyYAML's YAML
    1.1 rules: ``1e9`` and ``.5`` are numbers, ``yes`` / ``on`` and ``2024-01-01`` are text,
    ``010`` is ten."""

    yaml_implicit_resolvers: dict[Any, list[tuple[str, re.Pattern[str]]]] = {}  # noqa: RUF012

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Hashable, Any]:
        """The mapping, or a `LocatedError` at the line of a key's second occurrence."""
        seen: dict[Hashable, yaml.Node] = {}
        for key_node, _ in node.value:
            if key_node.tag == _MERGE_TAG:  # `<<: *anchor`; its keys may be overridden
                continue
            key = self.construct_object(key_node, deep=deep)
            if isinstance(key, Hashable) and key in seen:
                first = seen[key].start_mark.line + 1
                line = key_node.start_mark.line + 1
                raise LocatedError(
                    f"line {line}", f"duplicate key {key!r} (first at line {first})"
                )
            if isinstance(key, Hashable):
                seen[key] = key_node
        return yaml.constructor.SafeConstructor.construct_mapping(self, node, deep=deep)


def _core_schema(loader: type[yaml.SafeLoader]) -> None:
    """Resolve plain scalars in `loader` by the YAML 1.2 core schema (spec 10.3.2): null,
    bool, int (decimal, 0o octal, 0x hex) and float (with or without a point or an exponent,
    .inf, .nan), plus PyYAML's merge key; anything else is a string."""
    resolvers = [
        ("tag:yaml.org,2002:null", r"^(?:~|null|Null|NULL|)$", ["~", "n", "N", ""]),
        ("tag:yaml.org,2002:bool", r"^(?:true|True|TRUE|false|False|FALSE)$", list("tTfF")),
        ("tag:yaml.org,2002:int", r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$",
         list("-+0123456789")),
        ("tag:yaml.org,2002:float",
         r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
         r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$", list("-+.0123456789")),
        (_MERGE_TAG, r"^(?:<<)$", ["<"]),
    ]
    for tag, pattern, first in resolvers:
        loader.add_implicit_resolver(tag, re.compile(pattern), first)
    loader.add_constructor("tag:yaml.org,2002:int", _core_int)


def _core_int(loader: yaml.SafeLoader, node: yaml.Node) -> int:
    """An int of the core schema: ``0o17`` octal, ``0x1f`` hex, else decimal (``010`` is 10,
    not YAML 1.1's octal 8); a `YamlBoundError` over `MAX_INT_DIGITS` digits (Python refuses
    to convert over 4300, and no count or seed needs more than 20)."""
    text = str(loader.construct_scalar(node))  # type: ignore[arg-type]
    digits = len(text.lstrip("+-").removeprefix("0o").removeprefix("0x"))
    if digits > MAX_INT_DIGITS:
        raise YamlBoundError(node.start_mark.line + 1,
                             f"an integer of {digits} digits: at most {MAX_INT_DIGITS}")
    if text.startswith(("0o", "0x")):
        return int(text[2:], 8 if text[1] == "o" else 16)
    return int(text, 10)


_core_schema(_StrictLoader)


def parse_value(text: str) -> Any:
    """One YAML value as the scenario files read it (`_StrictLoader`: the core schema, the
    same bounds), for a value given on the command line (`--set PATH=VALUE`). Raises
    `yaml.YAMLError` (a `YamlBoundError` past a bound)."""
    check_events(text)
    return yaml.load(text, Loader=_StrictLoader)


def read_raw(path: Path) -> dict[str, Any]:
    """The file's YAML as a mapping, or a `LocatedError` keyed `(file)` or `line N`."""
    try:
        text = read_bounded(path, MAX_FILE_BYTES).decode("utf-8")
    except UnreadableFileError as exc:
        raise LocatedError(FILE_KEY, exc.problem) from None
    except UnicodeDecodeError:
        raise LocatedError(FILE_KEY, "not UTF-8 text") from None
    try:
        check_events(text)
        data = yaml.load(text, Loader=_StrictLoader)
    except YamlBoundError as exc:
        raise LocatedError(f"line {exc.line}", exc.problem) from None
    except yaml.MarkedYAMLError as exc:
        raise _yaml_problem(exc) from None
    except yaml.reader.ReaderError as exc:
        raise _reader_problem(exc, text) from None
    except yaml.YAMLError as exc:
        raise LocatedError(FILE_KEY, "YAML error: " + " ".join(str(exc).split())) from None
    if data is None:
        raise LocatedError(FILE_KEY, "empty file")
    if not isinstance(data, dict):
        raise LocatedError(
            FILE_KEY, f"must be a mapping of keys (format, name, ...), got {show(data)}"
        )
    return data


def _reader_problem(exc: yaml.reader.ReaderError, text: str) -> LocatedError:
    """`line N: YAML does not allow the character #xHHHH` (a NUL, a control character)."""
    char = exc.character
    code = char if isinstance(char, int) else ord(char)
    if yaml.__with_libyaml__:  # libyaml counts the position in bytes, PyYAML's reader in
        line = text.encode("utf-8")[: exc.position].count(b"\n") + 1  # characters
    else:
        line = text[: exc.position].count("\n") + 1
    return LocatedError(f"line {line}", f"YAML does not allow the character #x{code:04x}")


def _yaml_problem(exc: yaml.MarkedYAMLError) -> LocatedError:
    """`line N: YAML syntax error: <what> (<context> at line M)` from PyYAML's error."""
    mark = exc.problem_mark or exc.context_mark
    key = f"line {mark.line + 1}" if mark is not None else FILE_KEY
    what = exc.problem or exc.context or "malformed YAML"
    if exc.problem and exc.context and exc.context_mark is not None:
        what += f" ({exc.context} at line {exc.context_mark.line + 1})"
    return LocatedError(key, f"YAML syntax error: {what}")

