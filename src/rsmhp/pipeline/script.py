"""Glue for Snakemake rule scripts: logging to the rule's log file, errors recorded there, and
the code stamp of every output (:mod:`rsmhp.pipeline.code_digest`)."""

from __future__ import annotations

import logging
import os
import sys
import time
from collections.abc import Iterator
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Any

__all__ = ["rule_logging"]

# Expected failures, logged as their message alone: (module, class). Looked up in
# sys.modules when an exception arrives (a class whose module was never imported cannot have
# been raised), so that this module imports neither: every rule script imports it, and an
# import here would make every rule depend on that module's code (rsmhp.pipeline.code_digest).
_EXPECTED = (
    ("rsmhp.pipeline.io", "IntermediateFileError"),
    ("rsmhp.pipeline.config", "ConfigError"),
    ("rsmhp.report.verify", "VerificationError"),
)


def _expected() -> tuple[type[BaseException], ...]:
    found = (getattr(sys.modules.get(m), n, None) for m, n in _EXPECTED)
    return tuple(c for c in found if isinstance(c, type))


def _script_paths(job: Any) -> tuple[Path | None, Path, Path]:
    """(this job's script, the workflow's scripts directory, the src/ its jobs import from).
    Snakemake runs a script with ``__file__`` set to its real path."""
    from rsmhp.pipeline.code_digest import workflow_src

    scripts = Path(job.scriptdir).resolve()
    src = workflow_src(scripts)
    main = getattr(sys.modules.get("__main__"), "__file__", None)
    script = Path(main).resolve() if main else None
    if script is None or script.parent != scripts or not script.is_file():
        script = None
    return script, scripts, src


def _check_code(job: Any, log: logging.Logger) -> str | None:
    """Refuse a job whose code changed after the workflow was parsed and inputs made by
    mixed or outdated code (:func:`rsmhp.pipeline.contracts.check_codes`); return the stamp
    ``<rule>:<digest>`` its outputs record (None without a ``code`` param)."""
    from rsmhp.pipeline.code_digest import code_digest, method_only, split_stamp_rule
    from rsmhp.pipeline.contracts import check_codes
    from rsmhp.pipeline.io import IntermediateFileError

    code = getattr(job.params, "code", None)
    families = getattr(job.params, "families", None)
    script, scripts, src = _script_paths(job)
    if code is not None and script is not None:
        now = code_digest(script, src, method_only(families))
        if now != code:
            raise IntermediateFileError(
                f"{script.name}: the code of rule {job.rule} changed after the workflow was "
                f"parsed (digest {code} then, {now} now); nothing was computed: run snakemake "
                "again, it reruns what the change affects"
            )

    def current(stamp_rule: str) -> str | None:
        rule, fams = split_stamp_rule(stamp_rule)
        path = scripts / f"{rule}.py"
        return code_digest(path, src, method_only(fams)) if path.is_file() else None

    stamps = check_codes(list(job.input), current)
    if stamps:
        log.info("inputs made by: %s", ", ".join(sorted(set(stamps.values()))))
    if code is None:
        return None
    log.info("code %s", code)
    restricted = "" if families is None else "+" + ",".join(sorted(families))
    return f"{job.rule}{restricted}:{code}"


@contextmanager
def rule_logging(job: Any, rule: str | None = None) -> Iterator[logging.Logger]:
    """Send ``logging`` (INFO and up) to the rule's log file and stderr for the duration of a
    rule script: ``rule_logging(snakemake)`` in a script (or ``rule_logging(log_path, rule)``:
    logging only).

    Given the ``snakemake`` object, before the block runs: the job is refused if its code
    changed after the workflow was parsed (``params.code`` against the digest of the script's
    code now), and its inputs are refused if they were made by different or outdated code
    (:func:`rsmhp.pipeline.contracts.check_codes`). Within the block every table written through
    :mod:`rsmhp.pipeline.io` records ``<rule>:<params.code>``.

    An *expected* failure (a corrupt, incomplete or stale intermediate,
    :class:`rsmhp.pipeline.io.IntermediateFileError`; an invalid configuration,
    :class:`rsmhp.pipeline.config.ConfigError`; a run that disagrees with the committed reference,
    :class:`rsmhp.report.verify.VerificationError`) is logged as its message alone and ends the
    script with
    exit status 1: the message names the file or key and what to do, a traceback would only
    bury it. Any other exception is logged with its traceback and re-raised (a bug). Either
    way Snakemake marks the job failed (and removes its outputs; they are written atomically,
    so no half-written file is ever left).
    """
    if isinstance(job, str | os.PathLike):
        log_path, job = job, None
    else:
        log_path, rule = job.log[0], job.rule
    Path(log_path).parent.mkdir(parents=True, exist_ok=True)
    handlers = [
        logging.FileHandler(log_path, mode="w", encoding="utf-8"),
        logging.StreamHandler(sys.stderr),
    ]
    fmt = logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s")
    root = logging.getLogger()
    for h in handlers:
        h.setFormatter(fmt)
        root.addHandler(h)
    root.setLevel(logging.INFO)
    log = logging.getLogger(f"rsmhp.rule.{rule}")
    start = time.perf_counter()
    log.info("start")
    try:
        with ExitStack() as stack:
            if job is not None:
                from rsmhp.pipeline.io import stamping

                stack.enter_context(stamping(_check_code(job, log)))
            yield log
    except Exception as exc:
        if isinstance(exc, _expected()):
            log.error("failed: %s", exc)
            raise SystemExit(1) from None
        log.exception("failed")
        raise
    else:
        log.info("done in %.2f s", time.perf_counter() - start)
    finally:
        for h in handlers:
            root.removeHandler(h)
            h.close()
