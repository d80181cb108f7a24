"""Rule verify: compare this run's claims with the committed reference paper/claims.json."""

from pathlib import Path

from rsmhp.pipeline.script import rule_logging
from rsmhp.report.verify import VerificationError, verify

with rule_logging(snakemake) as log:
    try:
        ok, text = verify(snakemake.input.reference, snakemake.input.run)
    except ValueError as exc:
        raise VerificationError(str(exc)) from None
    log.info("\n%s", text)
    print(text)
    if not ok:
        raise VerificationError(
            "this run disagrees with the reference (table above and in "
            f"{snakemake.log[0]}); a flipped verdict or a number outside its tolerance"
        )
    Path(snakemake.output[0]).write_text(text, encoding="utf-8")
