# The replication report: results/paper/replication.md (main text), appendix.md, the figures
# they show, the claims with their key numbers (claims.json) and the README's glance table.
# `make publish` copies them to paper/ and README.md (tracked); a replication never touches
# tracked files. `make verify` (rule verify) compares claims.json with paper/claims.json.


HISTORY = "paper/history.csv"


rule report:
    """The replication report (main text, appendix, figures, claims) from every section."""
    input:
        sections=list(REPORT_SECTIONS.values()),
        figures=expand("results/figures/{name}.png", name=REPORT_FIGURES),
        # every earlier verdict of each claim (committed; make publish adds this run's)
        history=[HISTORY] if os.path.exists(HISTORY) else [],
        # the best family per cell of the summary figure (scenarios study)
        best=["results/scenarios/best.csv"] if "scenarios" in REPORT_SECTIONS else [],
    output:
        report="results/paper/replication.md",
        appendix="results/paper/appendix.md",
        claims="results/paper/claims.json",
        glance="results/paper/glance.md",
        # the HTML report's landing page (workflow/report/workflow.rst includes it)
        summary=_in_report(
            "results/paper/summary.html",
            caption="../report/summary.rst",
            category="1 Summary",
            labels={"item": "What we found"},
        ),
        figures=expand("results/paper/figures/{name}.png", name=REPORT_FIGURES),
        provenance="results/provenance.json",
    log:
        "results/logs/report.log",
    benchmark:
        "results/benchmarks/report.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    params:
        config=canonical(NUMBERS_CONFIG),
        # the preregistration the confirmatory claims were judged under (claims.json,
        # make verify): path and sha256 (the script adds the commit that added it)
        preregistration=(
            {k: CONFIRM[k] for k in ("path", "sha256")} if CONFIRM is not None else {}
        ),
        code=code_digest("workflow/scripts/report.py"),
    script:
        "../scripts/report.py"


rule verify:
    """Compare this run's claims with the committed paper/claims.json, claim by claim (make verify)."""
    input:
        run="results/paper/claims.json",
        reference="paper/claims.json",
    output:
        "results/verify.md",
    log:
        "results/logs/verify.log",
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    params:
        code=code_digest("workflow/scripts/verify.py"),
    script:
        "../scripts/verify.py"
