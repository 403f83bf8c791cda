"""zenav in Foxglove: its messages as Foxglove's well-known schemas (:mod:`.scene`),
written into recordings (:mod:`.recording`) and served live (``zenav foxglove``)."""
