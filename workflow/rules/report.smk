# The replication report: results/paper/replication.md plus the figures it shows.
# `make publish` copies it to paper/ (tracked); a replication never touches tracked files.


rule report:
    """The replication report results/paper/replication.md and its figures, from every section."""
    input:
        sections=list(REPORT_SECTIONS.values()),
        figures=expand("results/figures/{name}.png", name=REPORT_FIGURES),
    output:
        report="results/paper/replication.md",
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
        config=canonical(config),
    script:
        "../scripts/report.py"
