# The replication report: paper/replication.md plus the figures it shows.


rule report:
    """The replication report paper/replication.md and its figures, from every section."""
    input:
        sections=list(REPORT_SECTIONS.values()),
        figures=expand("results/figures/{name}.png", name=REPORT_FIGURES),
    output:
        report="paper/replication.md",
        figures=expand("paper/figures/{name}.png", name=REPORT_FIGURES),
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
