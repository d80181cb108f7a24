"""Glue for Snakemake rule scripts: logging to the rule's log file, errors recorded there."""

from __future__ import annotations

import logging
import os
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["rule_logging"]


@contextmanager
def rule_logging(log_path: str | os.PathLike, rule: str) -> Iterator[logging.Logger]:
    """Send ``logging`` (INFO and up) to ``log_path`` and stderr for the duration of a rule script.

    An *expected* failure (a corrupt or incomplete intermediate,
    :class:`rsmhp.io.IntermediateFileError`; an invalid configuration,
    :class:`rsmhp.config.ConfigError`; a run that disagrees with the committed reference,
    :class:`rsmhp.verify.VerificationError`) is logged as its message alone and ends the script with
    exit status 1: the message names the file or key and what to do, a traceback would only
    bury it. Any other exception is logged with its traceback and re-raised (a bug). Either
    way Snakemake marks the job failed (and removes its outputs; they are written atomically,
    so no half-written file is ever left).
    """
    from rsmhp.config import ConfigError
    from rsmhp.io import IntermediateFileError
    from rsmhp.verify import VerificationError

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
        yield log
    except (IntermediateFileError, ConfigError, VerificationError) as exc:
        log.error("failed: %s", exc)
        raise SystemExit(1) from None
    except Exception:
        log.exception("failed")
        raise
    else:
        log.info("done in %.2f s", time.perf_counter() - start)
    finally:
        for h in handlers:
            root.removeHandler(h)
            h.close()
