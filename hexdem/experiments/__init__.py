"""Studies built from single runs: one impact end to end (:mod:`.run`), the engine cross-check (:mod:`.compare`),
wavefront snapshots (:mod:`.snapshots`)."""
