"""``fsarm reproduce``: the seed papers' claims, checked on the simulator with the papers' own
procedures (issue 12). Claims are data (``fsarm_sim/data/claims/000.toml`` ... ``004.toml``, read by
:mod:`.claims_file`), measurements are
separate functions (:mod:`.measure000` ... :mod:`.measure004`), verdict rules live in
:mod:`.claims`, and :mod:`.runner` runs them and writes the report."""
