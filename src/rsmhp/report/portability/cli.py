"""``python -m rsmhp.report.portability`` (``make portability``): the drill's command line, run
as named steps: parse the arguments (:func:`_parser`), locate the runs (:func:`_locate`), set
up the emulated environment (:func:`_environments`), run the native and the emulated workflow
(:func:`_run_workflows`), load the three claims files (:func:`_load_claims`), compare
(:func:`_assemble`), write the report (:func:`_write`)."""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import textwrap
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rsmhp.pipeline.code_digest import rule_scripts
from rsmhp.report.portability.compare import compare_claims, compare_results, section_claims
from rsmhp.report.portability.emulation import (
    COMPONENTS,
    DEFAULT_CORETYPE,
    copy_workflow,
    emulation_env,
    install_hook,
    numba_cache_targets,
    probe,
    provenance_blas,
    read_records,
    summarise_emulation,
)
from rsmhp.report.portability.render import render

__all__ = ["DRILL_DIR", "ROOT", "main"]

#: the checkout whose Snakefile the drill runs (the package's own, like rsmhp.report.provenance)
ROOT = Path(__file__).resolve().parents[4]

#: subdirectory of the emulated working directory holding the drill's own files
DRILL_DIR = ".drill"

#: the variables of the emulated environment the report shows
_SHOWN = ("NUMBA_CPU_NAME", "NUMBA_CACHE_DIR", "OPENBLAS_CORETYPE", "NPY_DISABLE_CPU_FEATURES")


class _Abort(Exception):
    """The drill cannot go on (exit status 2); the message says why."""


@dataclass
class _Plan:
    """The parsed arguments and the resolved places of one drill."""

    args: argparse.Namespace
    components: set[str]
    native_dir: Path
    configfiles: list[str]
    checkout: Path
    output: Path
    reference: Path
    temporary: bool
    workdir: Path
    #: when the emulated run started (time.time()): report sections written since are its own
    started: float | None = None

    @property
    def drill_dir(self) -> Path:
        return self.workdir / DRILL_DIR


@dataclass
class _Environments:
    """The native and the emulated environment, each with its probe (:func:`probe`)."""

    native: dict[str, str]
    native_probe: dict[str, Any]
    emulated: dict[str, str]
    emulated_probe: dict[str, Any]
    snakefile: Path
    shown: dict[str, str]


def _add_run_options(p: argparse.ArgumentParser) -> None:
    """The runs compared: where, with what reference, configuration and targets."""
    p.add_argument("--native", default=".", help="working directory of the native run (.)")
    p.add_argument(
        "--no-native-run",
        action="store_true",
        help="only read the native results (default: complete them with snakemake first)",
    )
    p.add_argument(
        "--workdir",
        default=None,
        help="working directory of the emulated run (kept; default: a temporary directory, "
        "removed afterwards unless --keep); reused when it holds an earlier drill",
    )
    p.add_argument("--keep", action="store_true", help="keep the temporary emulated run")
    p.add_argument(
        "--reference", default="paper/claims.json", help="claims file (paper/claims.json)"
    )
    p.add_argument("--configfile", nargs="*", default=[], help="snakemake --configfile FILE(s)")
    p.add_argument("--cores", type=int, default=2, help="snakemake -j of both runs (2)")
    p.add_argument(
        "--target",
        nargs="+",
        default=["report", "frontier_reference"],
        help="snakemake targets of both runs (default: report and frontier_reference, what "
        "make verify and make publish need: every table and claim, the comparison's "
        "reference; `all` adds the recordings). Targets without the report, e.g. "
        "results/report/uav.json, drill those studies only: the claims of the report "
        "sections the emulated run made and its tables (the native run makes the report too)",
    )


def _add_other_options(p: argparse.ArgumentParser) -> None:
    """What is emulated, where the report goes, which checkout runs, and quiet."""
    p.add_argument(
        "--openblas-coretype",
        default=DEFAULT_CORETYPE,
        help=f"OPENBLAS_CORETYPE of the emulated run ({DEFAULT_CORETYPE})",
    )
    p.add_argument(
        "--emulate",
        default=",".join(COMPONENTS),
        help="what to emulate, a comma-separated subset of numba (generic target CPU), "
        "openblas (--openblas-coretype), numpy (SIMD dispatch off); default all three",
    )
    p.add_argument(
        "--output",
        default=None,
        help="report path without suffix, writes .md and .json "
        "(default <native>/results/portability/drill)",
    )
    p.add_argument(
        "--checkout",
        default=str(ROOT),
        help="the checkout whose workflow runs (default: the one rsmhp is imported from)",
    )
    p.add_argument("--quiet", action="store_true", help="do not echo snakemake's output")


def _parser() -> argparse.ArgumentParser:
    """The command line; its description is the first paragraph of the package's docstring."""
    from rsmhp.report import portability

    p = argparse.ArgumentParser(
        prog="python -m rsmhp.report.portability",
        description=" ".join(portability.__doc__.split("\n\n")[0].split()).replace("``", "`"),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=textwrap.dedent(
            """\
            examples:
              python -m rsmhp.report.portability     # full config: results/ vs paper/claims.json
              python -m rsmhp.report.portability --configfile tests/config/tiny.yaml \\
                  --native /tmp/tiny --reference /tmp/tiny/results/paper/claims.json \\
                  --output /tmp/tiny-drill/drill"""
        ),
    )
    _add_run_options(p)
    _add_other_options(p)
    return p


def _locate(args: argparse.Namespace, components: set[str]) -> _Plan:
    """Resolve the native run, configuration, checkout, output and reference, and choose the
    emulated working directory: ``--workdir`` (of its own, empty or an earlier drill's) or a
    new temporary directory (made last, after every check)."""
    native_dir = Path(args.native).resolve()
    output = Path(args.output) if args.output else native_dir / "results/portability/drill"
    if output.suffix in (".md", ".json"):
        output = output.with_suffix("")
    reference = Path(args.reference)
    made_by_native = reference.resolve().is_relative_to(native_dir / "results")
    if not reference.is_file() and not (made_by_native and not args.no_native_run):
        raise _Abort(f"reference {reference} not found")
    workdir = Path(args.workdir).resolve() if args.workdir else None
    if workdir is not None:
        if workdir == native_dir or native_dir.is_relative_to(workdir):
            raise _Abort("the emulated run needs a directory of its own")
        if workdir.exists() and any(workdir.iterdir()) and not (workdir / DRILL_DIR).is_dir():
            raise _Abort(f"{workdir} is not empty and holds no drill")
    else:
        workdir = Path(tempfile.mkdtemp(prefix="rsmhp-portability-")).resolve()
    return _Plan(
        args=args,
        components=components,
        native_dir=native_dir,
        configfiles=[str(Path(c).resolve()) for c in args.configfile],
        checkout=Path(args.checkout).resolve(),
        output=output,
        reference=reference,
        temporary=args.workdir is None,
        workdir=workdir,
    )


def _environments(plan: _Plan) -> _Environments:
    """Probe this environment, install the hook, copy the workflow and make (and probe) the
    emulated environment of the chosen components."""
    native_env = dict(os.environ)
    native_probe = probe(native_env)
    plan.drill_dir.mkdir(parents=True, exist_ok=True)
    install_hook(plan.drill_dir)
    snakefile = copy_workflow(plan.checkout, plan.drill_dir / "workflow")
    env = emulation_env(
        native_env,
        plan.drill_dir,
        plan.args.openblas_coretype if "openblas" in plan.components else None,
        native_probe.get("numpy_dispatch", []) if "numpy" in plan.components else (),
        numba="numba" in plan.components,
    )
    emulated_probe = probe(env)
    shown_env = {k: env[k] for k in _SHOWN if k in env}
    print(f"portability: emulated environment {shown_env}", flush=True)
    return _Environments(native_env, native_probe, env, emulated_probe, snakefile, shown_env)


def _snakemake_cmd(workdir: Path, snakefile: Path, configfiles: Sequence[str]) -> list[str]:
    """``python -m snakemake`` of ``snakefile`` in ``workdir`` with ``configfiles``."""
    cmd = [sys.executable, "-m", "snakemake", "-s", str(snakefile), "-d", str(workdir)]
    return cmd + (["--configfile", *configfiles] if configfiles else [])


def _snakemake(
    workdir: Path,
    snakefile: Path,
    configfiles: Sequence[str],
    cores: int,
    targets: Sequence[str],
    env: Mapping[str, str],
    log: Path | None,
    quiet: bool,
) -> int:
    """Run ``snakemake`` in ``workdir`` (echoed unless ``quiet``, appended to ``log``); its
    exit status (a failure shows the last 41 lines of its output even when ``quiet``)."""
    # targets after an option: after --configfile's files they would be read as files
    cmd = [*_snakemake_cmd(workdir, snakefile, configfiles), f"-j{cores}", *targets]
    print("$ " + " ".join(cmd), flush=True)
    fh = open(log, "a", encoding="utf-8") if log else None
    try:
        proc = subprocess.Popen(
            cmd, env=dict(env), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
        )
        assert proc.stdout is not None
        tail: list[str] = []
        for line in proc.stdout:
            if fh:
                fh.write(line)
            if not quiet:
                sys.stdout.write(line)
            tail = [*tail[-40:], line]
        code = proc.wait()
    finally:
        if fh:
            fh.close()
    if code != 0 and quiet:
        sys.stdout.write("".join(tail))
    return code


_LABEL = re.compile(r'label = "(\w+)"')


def _target_scripts(plan: _Plan, envs: _Environments) -> list[Path]:
    """The rule scripts of every job the drill's targets need, from the workflow copy's rule
    graph for those targets (``snakemake --rulegraph``: parsed, no job run)."""
    cmd = _snakemake_cmd(plan.workdir, envs.snakefile, plan.configfiles)
    cmd += ["--rulegraph", "dot", *plan.args.target]
    res = subprocess.run(cmd, env=envs.native, capture_output=True, text=True, check=False)
    rules = set(_LABEL.findall(res.stdout))
    if res.returncode or not rules:
        raise _Abort(f"the rule graph of {plan.args.target} failed: {res.stderr[-2000:]}")
    scripts = rule_scripts(envs.snakefile.parent / "workflow")
    return sorted(scripts[r] for r in rules if r in scripts)


def _run_workflows(plan: _Plan, envs: _Environments) -> None:
    """Complete the native run with the checkout's workflow (unless ``--no-native-run``), then
    make the emulated run with the copy, logged to ``<drill>/snakemake.log``."""
    args = plan.args
    if not args.no_native_run:
        print("portability: completing the native run", flush=True)
        # the native run is make verify's: its report too, whatever the emulated run's targets
        full = _whole_report(args.target)
        code = _snakemake(
            plan.native_dir,
            plan.checkout / "Snakefile",
            plan.configfiles,
            args.cores,
            [*args.target, *([] if full else ["report"])],
            envs.native,
            None,
            args.quiet,
        )
        if code:
            raise _Abort("the native run failed")
    print(f"portability: emulated run in {plan.workdir}", flush=True)
    plan.started = time.time()
    log = plan.drill_dir / "snakemake.log"
    # compile the emulated CPU's kernels first, on every core (rsmhp.pipeline.warm): the
    # workflow's jobs would each compile what they call, two at once compiling the same kernel.
    # From the copy's src/, first on the path as in its jobs: numba's cache is keyed on the
    # source file, so kernels compiled from the checkout's src/ would not be the jobs'
    warm = [sys.executable, "-m", "rsmhp.pipeline.warm", "--cores", str(args.cores)]
    scripts = None if _whole_report(args.target) else _target_scripts(plan, envs)
    if scripts is not None:  # some studies: only the kernels their jobs' scripts can import
        warm += ["--scripts", *map(str, scripts)]
    src = str(envs.snakefile.parent / "src")
    path = os.pathsep.join(filter(None, [src, envs.emulated.get("PYTHONPATH")]))
    if scripts == []:
        print("portability: the targets' rules run no script: no kernel to compile", flush=True)
    elif subprocess.run(warm, env={**envs.emulated, "PYTHONPATH": path}, check=False).returncode:
        raise _Abort("compiling the kernels for the emulated CPU failed")
    if _snakemake(
        plan.workdir,
        envs.snakefile,
        plan.configfiles,
        args.cores,
        args.target,
        envs.emulated,
        log,
        args.quiet,
    ):
        raise _Abort(f"the emulated run failed (log {log})")


@dataclass
class _Claims:
    """The claims compared: the reference's, the native and the emulated run's, their
    configuration's sha256, and the report sections they come from (None: the whole report,
    ``results/paper/claims.json``; else the sections the emulated run's targets made)."""

    reference: list[Any]
    native: list[Any]
    emulated: list[Any]
    config_hash: str
    sections: list[str] | None
    #: the whole reference's statistical claims (make verify's tolerance counts them all)
    n_statistical: int | None = None


def _load_claims(plan: _Plan) -> _Claims:
    """The claims of the three runs, all of the same configuration. When the emulated run made
    the report, every claim of the three ``claims.json``; when its targets made only some report
    sections (``results/report/<study>.json``), the claims of those sections, from the
    same sections of the native run, and the reference's claims of the same ids. A claim the
    report changes (a Holm family's adjusted p-value) cannot be checked from its section: such
    a section is refused, naming the claims."""
    from rsmhp.report.verify import load_claims

    try:
        ref_claims, ref_hash = load_claims(plan.reference)
        nat_claims, nat_hash = load_claims(plan.native_dir / "results/paper/claims.json")
        if _whole_report(plan.args.target):
            emu_claims, emu_hash = load_claims(plan.workdir / "results/paper/claims.json")
            sections = None
        else:
            emu_by = section_claims(plan.workdir / "results/report")
            nat_by = section_claims(plan.native_dir / "results/report")
            made = target_sections(plan.args.target, plan.workdir, plan.started)
            emu_by = {s: c for s, c in emu_by.items() if s in made}
            sections, emu_hash = sorted(emu_by), nat_hash
    except ValueError as exc:
        raise _Abort(str(exc)) from exc
    if len({ref_hash, nat_hash, emu_hash}) != 1:
        raise _Abort(
            f"config sha256 differs (reference {ref_hash}, native {nat_hash}, "
            f"emulated {emu_hash}): compare runs of the same configuration"
        )
    if sections is None:
        return _Claims(ref_claims, nat_claims, emu_claims, ref_hash, None)
    if not sections:
        raise _Abort(
            f"the targets {' '.join(plan.args.target)} make neither results/paper/claims.json "
            "nor a report section (results/report/<study>.json): no claim to compare"
        )
    missing = [s for s in sections if s not in nat_by]
    if missing:
        raise _Abort(f"the native run has no report section {', '.join(missing)}")
    emu_claims = [c for s in sections for c in emu_by[s]]
    reported = {c.id: c for c in nat_claims}  # the native report's, loaded above
    nat_claims = [c for s in sections for c in nat_by[s]]
    changed = [c.id for c in nat_claims if c.id in reported and not _same(c, reported[c.id])]
    if changed:
        raise _Abort(
            f"the report changes the claims {', '.join(changed)} of these sections (a Holm "
            "family's adjusted p-values): drill them with --target report"
        )
    ids = {c.id for c in [*nat_claims, *emu_claims]}
    scoped = [c for c in ref_claims if c.id in ids]
    n_stat = sum(c.key.reproducible == "statistical" for c in ref_claims)
    return _Claims(scoped, nat_claims, emu_claims, ref_hash, sections, n_stat)


def _whole_report(targets: Sequence[str]) -> bool:
    """Whether the targets make the whole report: ``report``, ``all``, ``verify`` (it
    compares the report's claims), or a file of ``results/paper/``, ``results/verify.md`` or
    ``results/provenance.json`` (the report rule's)."""
    files = {"results/verify.md", "results/provenance.json"}
    return bool({"report", "all", "verify"} & set(targets)) or any(
        t.removeprefix("./").startswith("results/paper/") or t.removeprefix("./") in files
        for t in targets
    )


def target_sections(
    targets: Sequence[str], workdir: str | os.PathLike, since: float | None
) -> set[str]:
    """The report sections a drill of ``targets`` compares: those the targets name
    (``results/report/<study>.json``) and those the emulated run in ``workdir`` wrote at or
    after ``since`` (other targets, e.g. a study's rule, make theirs). A section an earlier
    drill left in a reused working directory is neither, and is not compared; so neither is
    one a rule target made in an earlier drill there and left up to date (name the section
    file as a target to compare it)."""
    named = {Path(t).stem for t in targets if re.fullmatch(r"(\./)?results/report/\w+\.json", t)}
    report = Path(workdir) / "results" / "report"
    fresh = {
        p.stem
        for p in report.glob("*.json")
        if since is not None and p.stat().st_mtime >= since - 1.0  # coarse file-system clocks
    }
    return named | fresh


def _same(a: Any, b: Any) -> bool:
    """Whether two claims hold the same fields (NaN equal to NaN, as in their JSON)."""
    from dataclasses import asdict

    return json.dumps(asdict(a), sort_keys=True, default=str) == json.dumps(
        asdict(b), sort_keys=True, default=str
    )


def _summarise(plan: _Plan, envs: _Environments) -> dict[str, Any]:
    """What the emulation changed, as measured (:func:`summarise_emulation`)."""
    return summarise_emulation(
        envs.native_probe,
        envs.emulated_probe,
        read_records(plan.drill_dir / "records"),
        numba_cache_targets(plan.drill_dir / "numba-cache"),
        provenance_blas(plan.native_dir / "results"),
        provenance_blas(plan.workdir / "results"),
        plan.components,
    )


def _assemble(plan: _Plan, envs: _Environments) -> dict[str, Any]:
    """The drill: the emulation as measured, every claim and table compared, and the result
    (``PASS`` when both runs pass verify with the same verdicts)."""
    loaded = _load_claims(plan)
    emulation = _summarise(plan, envs)
    claims = compare_claims(loaded.reference, loaded.native, loaded.emulated, loaded.n_statistical)
    tables = compare_results(
        plan.native_dir / "results",
        plan.workdir / "results",
        emulated_only=loaded.sections is not None,
    )
    verify_native = all(r["verify (native)"] == "ok" for r in claims)
    verify_emulated = all(r["verify (emulated)"] == "ok" for r in claims)
    agree = all(r["same verdict"] for r in claims)
    result = "PASS" if verify_native and verify_emulated and agree else "FAIL"
    if not emulation["effective"]:
        result = "EMULATION NOT EFFECTIVE"
    removed = plan.temporary and not plan.args.keep
    return {
        "result": result,
        "native": str(plan.native_dir),
        "emulated": str(plan.workdir) + (" (temporary, removed)" if removed else ""),
        "reference": str(plan.reference),
        "config sha256": loaded.config_hash,
        "targets": list(plan.args.target),
        "sections": loaded.sections,
        "env": envs.shown,
        "verify native": "PASS" if verify_native else "FAIL",
        "verify emulated": "PASS" if verify_emulated else "FAIL",
        "verdicts agree": agree,
        "emulation": emulation,
        "claims": claims,
        "tables": tables,
    }


def _jsonable(x: Any) -> Any:
    """``x`` with numpy scalars as Python numbers and non-finite floats as None."""
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple | set):
        return [_jsonable(v) for v in x]
    if isinstance(x, float | np.floating):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


def _write(drill: Mapping[str, Any], output: Path) -> None:
    """Write ``<output>.md`` (:func:`render`, printed as well) and ``<output>.json``."""
    text = render(drill)
    md, js = Path(f"{output}.md"), Path(f"{output}.json")
    md.parent.mkdir(parents=True, exist_ok=True)
    md.write_text(text, encoding="utf-8")
    js.write_text(json.dumps(_jsonable(drill), indent=1) + "\n", encoding="utf-8")
    print(text)
    print(f"portability: wrote {md} and {js}")


def _drill(plan: _Plan) -> int:
    """Set up, run, compare and write; the exit status (see :func:`main`)."""
    envs = _environments(plan)
    _run_workflows(plan, envs)
    drill = _assemble(plan, envs)
    _write(drill, plan.output)
    if not drill["emulation"]["effective"]:
        return 3
    return 0 if drill["result"] == "PASS" else 1


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m rsmhp.report.portability``: see ``--help``. Exit status 0 when every verdict is
    the same and both runs pass verify, 1 when not, 2 when a run failed or the inputs cannot
    be compared, 3 when the emulation did not take effect."""
    p = _parser()
    args = p.parse_args(argv)
    components = {c.strip() for c in args.emulate.split(",") if c.strip()}
    if not components or components - set(COMPONENTS):
        p.error(f"--emulate: choose from {', '.join(COMPONENTS)}, got {args.emulate!r}")
    try:
        plan = _locate(args, components)
    except _Abort as exc:
        print(f"portability: {exc}", file=sys.stderr)
        return 2
    try:
        return _drill(plan)
    except _Abort as exc:
        print(f"portability: {exc}", file=sys.stderr)
        return 2
    finally:
        if plan.temporary and not args.keep:
            shutil.rmtree(plan.workdir, ignore_errors=True)
