"""One package per study: ``simulate`` (config -> tables), ``summarise`` (tables -> statistics),
``claims`` (key numbers and verdicts), ``figures`` and ``section`` (the report section). A
study builds on core, models, pipeline and report, never on another study."""
