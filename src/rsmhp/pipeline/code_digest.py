"""The digest of the package code a workflow rule depends on, so that a rule reruns exactly
when that code changes.

Snakemake reruns a job when its params, its inputs or its script change, never when a module
its script imports changes. Every rule that computes from :mod:`rsmhp` therefore carries the
digest of its code as a param (``code=code_digest("workflow/scripts/<rule>.py")`` via the
helper in ``workflow/rules/common.smk``), computed when the workflow is parsed; Snakemake's
``params`` rerun trigger then reruns the rule, and everything downstream, when the digest
changes. Its outputs record the digest (:mod:`rsmhp.pipeline.io`), aggregation rules refuse inputs
made by different or outdated code, and ``results/provenance.json`` lists it per rule.

What the digest covers. Starting from the rule's script, every ``import rsmhp...`` and ``from
rsmhp... import ...`` is followed statically (:mod:`ast`, no code is run), transitively,
wherever it is written (module level, inside functions, under ``if``/``try``: every module
the script *can* import), relative imports included; importing a module imports its parent
packages, so their ``__init__`` files are included too. A module that imports by a computed
name (``importlib.import_module(name)``, ``__import__``, ``pkgutil.iter_modules``), such as a
registry that imports every module of its package, counts as importing every module of its
package, unless the caller names the modules of that package the job can reach (``only``): a
rule that runs some UAV planning methods passes their family modules, so its digest covers the
method registry, its base and those families, and adding or editing another family's module
leaves it alone (the rule also passes them as its ``families`` param, with which the job checks
its code when it starts). The script and each module are hashed in a normalised form, their syntax
tree without positions (a stable rendering of :mod:`ast` that omits empty fields, so it does not
depend on the Python version's node layout): an edit that changes only comments, blank
lines, line breaks, quotes or other formatting keeps the digest; any change of code or of a
docstring changes it. The digest is the first 12 hex digits of a SHA-256 over the sorted
(module, module digest) pairs; it does not depend on where the checkout lives. Report templates
count as code of the modules that render them: a ``*.md`` file beside a covered module whose
code names it in a string constant (``render("rsmhp.studies.lqg", "section.md", ...)``,
:mod:`rsmhp.report.templates`) is hashed byte for byte under the name ``<package>/<file>``; a
prose edit reruns the rules whose code renders that template, and never a study's simulation
(its ``simulate`` modules render nothing). Not covered: third-party packages
(``results/provenance.json`` records
their versions), other data files the code reads, and modules reached only through a string
the analysis cannot see.

Why params and not the source files as rule inputs: Snakemake compares inputs by
modification time, so ``touch``, a ``git checkout`` of another branch and back, or a fresh
clone (every file new) would rerun every rule although no code changed. A content digest
reruns a rule exactly when the code its script imports changed, and leaves it alone after a
change to a module it does not import.

The per-module analysis (parse, normalise, hash, imports) is cached by the file's content
(SHA-256), per process and in ``src/rsmhp/__pycache__/code_digest.<python>.json`` (shared by
the workflow's jobs, each of which checks its code when it starts): parsing the workflow
stays fast, and an edited file is always analysed again.
"""

from __future__ import annotations

import ast
import contextlib
import hashlib
import json
import os
import re
import sys
import tempfile
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

__all__ = [
    "DIGEST_LENGTH",
    "METHOD_REGISTRY",
    "CodeDigest",
    "code_digest",
    "describe",
    "method_only",
    "module_digest",
    "rule_blocks",
    "rule_scripts",
    "split_stamp_rule",
    "workflow_src",
]

#: hex digits of a digest (48 bits: distinct versions of a rule's code never collide in practice)
DIGEST_LENGTH = 12

_PACKAGE = "rsmhp"
#: the UAV method registry: it imports every family module of its package by computed name
METHOD_REGISTRY = "rsmhp.models.uav.methods"
# calls that import a module whose name the analysis cannot read
_DYNAMIC = {"import_module", "__import__", "iter_modules", "walk_packages"}


@dataclass(frozen=True)
class CodeDigest:
    """The code a script depends on: ``digest`` (short hex) and ``modules``, every module it
    can import (dotted name; the script under its file name) with that module's digest."""

    script: str
    digest: str
    modules: dict[str, str] = field(default_factory=dict)

    def __str__(self) -> str:
        return self.digest


def _hex(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


_IMPORTS = (ast.Import, ast.ImportFrom, ast.Call)


def _render(node: ast.AST, out: list[str], found: list[ast.AST]) -> None:
    """Append a stable text of the syntax tree ``node`` to ``out``: node types and field
    values, no positions, empty fields (``None``, ``[]``) left out, so that the text is the
    same across Python versions for code that uses no new syntax. Import statements and calls
    met on the way are appended to ``found`` (one pass does both)."""
    cls = type(node)
    out.append(cls.__name__ + "(")
    if cls in _IMPORTS:
        found.append(node)
    for name in cls._fields:
        value = getattr(node, name, None)
        if value is None or (isinstance(value, list) and not value):
            continue
        out.append(name + "=")
        if isinstance(value, ast.AST):
            _render(value, out, found)
        elif isinstance(value, list):
            out.append("[")
            for item in value:
                if isinstance(item, ast.AST):
                    _render(item, out, found)
                else:
                    out.append(repr(item))
                out.append(",")
            out.append("]")
        else:
            out.append(repr(value))
        out.append(",")
    out.append(")")


@dataclass(frozen=True)
class _Module:
    digest: str
    # absolute module names this module imports (candidates: may name a function, not a
    # module; resolved against the file tree by the caller)
    imports: tuple[str, ...]
    dynamic: bool
    # file names ending in ".md" written as string constants in the module (the templates it
    # renders, :mod:`rsmhp.report.templates`)
    templates: tuple[str, ...] = ()


def _analyse(source: bytes, name: str, is_package: bool, disk: _DiskCache | None) -> _Module:
    """Digest and imports of one module's source, cached by content: in this process, and
    in ``disk`` (the package's ``__pycache__``, shared by the workflow's jobs)."""
    key = f"{_hex(source)} {name} {int(is_package)}"
    if disk is not None and (hit := disk.get(key)) is not None:
        return hit
    mod = _analyse_source(source, name, is_package)
    if disk is not None:
        disk.put(key, mod)
    return mod


@lru_cache(maxsize=4096)
def _analyse_source(source: bytes, name: str, is_package: bool) -> _Module:
    text: list[str] = []
    found: list[ast.AST] = []
    tree = ast.parse(source)
    _render(tree, text, found)
    package = name if is_package else name.rpartition(".")[0]
    imports: list[str] = []
    dynamic = False
    for node in found:
        if isinstance(node, ast.Import):
            imports.extend(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = package.split(".") if package else []
                if node.level - 1 > len(parts):
                    continue
                base = parts[: len(parts) - (node.level - 1)]
                module = ".".join([*base, node.module] if node.module else base)
            else:
                module = node.module or ""
            imports.append(module)
            imports.extend(f"{module}.{a.name}" for a in node.names if a.name != "*")
        elif isinstance(node, ast.Call):
            func = node.func
            called = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)
            if called in ("import_module", "__import__") and node.args:
                arg = node.args[0]
                if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                    imports.append(arg.value)
                    continue
            if called in _DYNAMIC:
                dynamic = True
    wanted = tuple(sorted({m for m in imports if m.split(".")[0] == _PACKAGE}))
    tree_strings = {
        n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)
    }
    templates = tuple(sorted(v for v in tree_strings if v.endswith(".md") and "/" not in v))
    return _Module(_hex("".join(text).encode()), wanted, dynamic, templates)


class _DiskCache:
    """Analysed modules by content hash in ``<src>/rsmhp/__pycache__`` (like Python's own
    bytecode cache; numba's sits there too), so that the workflow's jobs, which each check
    their code, do not parse every module again. Keyed by the source's SHA-256, so it can
    never serve an outdated analysis; unreadable or unwritable: not used."""

    _FORMAT = 2  # bump when the analysis changes
    _MAX = 4000  # entries kept (the oldest go first)

    def __init__(self, src: Path) -> None:
        tag = sys.implementation.cache_tag or "python"
        self.path = src / _PACKAGE / "__pycache__" / f"code_digest.{tag}.json"
        self.entries: dict[str, list] = {}
        self.new = 0
        try:
            data = json.loads(self.path.read_text(encoding="utf-8"))
            if data.get("format") == self._FORMAT:
                self.entries = dict(data["entries"])
        except (OSError, ValueError, KeyError, TypeError, AttributeError):
            pass

    def get(self, key: str) -> _Module | None:
        value = self.entries.get(key)
        if value is None:
            return None
        digest, imports, dynamic, templates = value
        return _Module(digest, tuple(imports), bool(dynamic), tuple(templates))

    def put(self, key: str, mod: _Module) -> None:
        self.entries[key] = [mod.digest, list(mod.imports), mod.dynamic, list(mod.templates)]
        self.new += 1

    def save(self) -> None:
        if not self.new:
            return
        entries = dict(list(self.entries.items())[-self._MAX :])
        try:
            self.path.parent.mkdir(exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=self.path.parent, prefix=".code_digest.")
            os.chmod(tmp, 0o644)
            with os.fdopen(fd, "w", encoding="utf-8") as fh:
                json.dump({"format": self._FORMAT, "entries": entries}, fh)
            os.replace(tmp, self.path)
            self.new = 0
        except OSError:
            with contextlib.suppress(OSError, UnboundLocalError):
                os.unlink(tmp)


_DISK: dict[Path, _DiskCache] = {}


def _disk(src: Path) -> _DiskCache | None:
    if not (src / _PACKAGE).is_dir():
        return None
    key = src.resolve()
    if key not in _DISK:
        _DISK[key] = _DiskCache(key)
    return _DISK[key]


#: _locate's answers, per (src, module name): the answer and the modification times of the
#: directories it depends on (a file added or removed in either changes them). The workflow
#: asks for the same modules once per rule (61 rules: about 6,000 lookups when it is parsed)
_LOCATED: dict[tuple[Path, str], tuple[tuple[int, int], tuple[Path, bool] | None]] = {}


def _mtime(path: str) -> int:
    try:
        return os.stat(path).st_mtime_ns
    except OSError:
        return -1


def _locate(name: str, src: Path) -> tuple[Path, bool] | None:
    """(file, is_package) of module ``name`` under ``src``, or None if it is not a module."""
    parts = name.split(".")
    parent = os.path.join(src, *parts[:-1])
    stamp = (_mtime(parent), _mtime(os.path.join(parent, parts[-1])))
    hit = _LOCATED.get((src, name))
    if hit is not None and hit[0] == stamp:
        return hit[1]
    base = src.joinpath(*parts)
    found: tuple[Path, bool] | None = None
    if (base / "__init__.py").is_file():
        found = base / "__init__.py", True
    elif base.with_suffix(".py").is_file():
        found = base.with_suffix(".py"), False
    _LOCATED[(src, name)] = (stamp, found)
    return found


def _package_modules(package: str, src: Path) -> list[str]:
    """Every module under package ``package`` (recursively)."""
    root = src.joinpath(*package.split("."))
    out = []
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(src).with_suffix("")
        parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
        if all(p.isidentifier() for p in parts):
            out.append(".".join(parts))
    return out


def _default_src() -> Path:
    """The directory holding this (imported) package."""
    return Path(__file__).resolve().parents[2]


_RULE_START = re.compile(r"\n(?=rule )")
_RULE_NAME = re.compile(r"rule (\w+):")
_SCRIPT = re.compile(r'^\s+script:\s*\n\s+"\.\./scripts/([\w.]+\.py)"', re.M)


def rule_blocks(workflow_dir: str | os.PathLike) -> dict[str, str]:
    """Rule name -> its text (up to the next rule) for every rule of
    ``<workflow_dir>/rules/*.smk``."""
    blocks = {}
    for smk in sorted(Path(workflow_dir, "rules").glob("*.smk")):
        for block in _RULE_START.split(smk.read_text(encoding="utf-8")):
            if m := _RULE_NAME.match(block):
                blocks[m.group(1)] = block
    return blocks


def rule_scripts(workflow_dir: str | os.PathLike) -> dict[str, Path]:
    """Rule name -> its ``script:`` (``<workflow_dir>/scripts/<file>.py``) for every rule of
    :func:`rule_blocks` that has one."""
    scripts = Path(workflow_dir, "scripts")
    return {
        name: scripts / m.group(1)
        for name, block in rule_blocks(workflow_dir).items()
        if (m := _SCRIPT.search(block))
    }


def workflow_src(scripts: str | os.PathLike) -> Path:
    """The ``src/`` of the workflow whose rule scripts are in ``scripts``
    (``<workflow>/workflow/scripts``): its jobs import ``rsmhp`` from there (the Snakefile
    puts it first on ``PYTHONPATH``). Outside a checkout, the imported package's directory."""
    src = Path(scripts).resolve().parents[1] / "src"
    return src if (src / _PACKAGE).is_dir() else _default_src()


def describe(
    script: str | os.PathLike,
    src: str | os.PathLike | None = None,
    only: Mapping[str, Iterable[str]] | None = None,
) -> CodeDigest:
    """The digest of ``script`` and of every ``rsmhp`` module under ``src`` it can import
    (``src`` is the directory holding the ``rsmhp`` package, by default the one this module
    was imported from; the workflow passes its own ``src/``). ``only`` maps a package that
    imports its modules by computed name (the method registry) to the modules of it that count
    (dotted names under that package); without an entry, all of its modules count. See the
    module docstring."""
    script, src = Path(script), Path(src) if src is not None else _default_src()
    only = {k: sorted(v) for k, v in (only or {}).items()}
    for package, names in only.items():
        stray = [n for n in names if not n.startswith(package + ".")]
        if stray:
            raise ValueError(f"code_digest: only[{package!r}]: {stray} are not modules of it")
    try:
        source = script.read_bytes()
    except OSError as exc:
        raise FileNotFoundError(f"code_digest: cannot read the script {script}: {exc}") from exc
    disk = _disk(src)
    top = _analyse(source, "__main__", False, disk)
    digests = {script.name: top.digest}
    todo = list(top.imports)
    seen: set[str] = set()
    rendered: dict[str, tuple[Path, str, tuple[str, ...]]] = {}
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        parts = name.split(".")
        todo.extend(".".join(parts[:i]) for i in range(1, len(parts)))  # parent packages
        found = _locate(name, src)
        if found is None:
            continue  # a name inside a module (``from rsmhp.x import function``)
        path, is_package = found
        mod = _analyse(path.read_bytes(), name, is_package, disk)
        digests[name] = mod.digest
        if mod.templates:
            rendered[name] = (path, name if is_package else name.rpartition(".")[0], mod.templates)
        todo.extend(mod.imports)
        if mod.dynamic:
            package = name if is_package else name.rpartition(".")[0]
            todo.extend(only[package] if package in only else _package_modules(package, src))
    if disk is not None:
        disk.save()
    for path, package, templates in rendered.values():
        for t in templates:
            if (path.parent / t).is_file():
                digests[f"{package}/{t}"] = _hex((path.parent / t).read_bytes())
    modules = dict(sorted(digests.items()))
    text = "".join(f"{k} {v}\n" for k, v in modules.items())
    return CodeDigest(script.name, _hex(text.encode())[:DIGEST_LENGTH], modules)


def code_digest(
    script: str | os.PathLike,
    src: str | os.PathLike | None = None,
    only: Mapping[str, Iterable[str]] | None = None,
) -> str:
    """The short hex digest of the code ``script`` runs: the script and every ``rsmhp``
    module it can import, in normalised form (see the module docstring; :func:`describe`
    lists the modules and explains ``only``)."""
    return describe(script, src, only).digest


def method_only(families: Iterable[str] | None) -> dict[str, list[str]] | None:
    """The ``only`` argument of :func:`describe` for a job that runs members of the method
    families ``families`` (their module names under :data:`METHOD_REGISTRY`, e.g.
    ``["monte_carlo", "nbo"]``); ``None`` (every family) for ``None``."""
    if families is None:
        return None
    return {METHOD_REGISTRY: [f"{METHOD_REGISTRY}.{f}" for f in sorted(set(families))]}


def split_stamp_rule(rule: str) -> tuple[str, list[str] | None]:
    """``(rule, families)`` of the rule part of an output's code stamp: ``uav_simulate+nbo``
    is rule ``uav_simulate`` restricted to the family ``nbo`` (see :func:`method_only`);
    ``report`` has no restriction (``None``)."""
    name, plus, families = rule.partition("+")
    return name, (families.split(",") if plus else None)


def module_digest(
    modules: Iterable[str],
    src: str | os.PathLike | None = None,
    only: Mapping[str, Iterable[str]] | None = None,
) -> CodeDigest:
    """The digest of the code that importing ``modules`` (dotted ``rsmhp`` module names) can
    run: :func:`describe` of a script whose only lines are ``import <module>``, one per
    module, sorted, so that the digest depends on the set of names and on the code they
    reach, not on the order or on where the script would live. ``src`` and ``only`` as for
    :func:`describe` (e.g. ``module_digest(["rsmhp.models.uav.simulation"],
    only=method_only(["nbo"]))``: the closed loop of the NBO family alone). A name that is
    not an ``rsmhp`` module under ``src`` is refused, naming it."""
    names = sorted({str(m) for m in modules})
    if not names:
        raise ValueError("module_digest: modules is empty (name at least one rsmhp module)")
    root = Path(src) if src is not None else _default_src()
    bad = [n for n in names if n.split(".")[0] != _PACKAGE or _locate(n, root) is None]
    if bad:
        raise ValueError(f"module_digest: {bad} are not {_PACKAGE} modules under {root}")
    text = "".join(f"import {n}\n" for n in names)
    with tempfile.TemporaryDirectory(prefix="code_digest.") as tmp:
        script = Path(tmp) / "modules.py"
        script.write_text(text, encoding="utf-8")
        return describe(script, root, only)
