"""Helpers every layer uses: number checks (:mod:`.checks`), atomic output (:mod:`.io`), progress bars
(:mod:`.progress`)."""
