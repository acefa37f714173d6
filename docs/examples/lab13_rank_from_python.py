"""lab13 (docs/matchmaking.md, "Tried by a researcher"): the matchmaker from Python on a researcher's own
OWL-S collection, as matchmaking.md's "From Python" shows it. The collection is loaded into a store of its
own (the service model without the bundled home), each query ranked by Sem-Str and by strict logic with
one parameter set, the first three candidates printed with their explanation, then the collection's
figures. Run from the checkout: python docs/examples/lab13_rank_from_python.py [COLLECTION]
"""

from __future__ import annotations

import sys
from pathlib import Path

from cbrs.reasoner import MatchConfig, Matchmaker
from cbrs.reasoner.owlstc import evaluate_collection, load_collection

folder = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent / "lab13_collection"
loaded = load_collection(folder)  # services/, queries/ and ontology/, in a fresh in-memory store
config = MatchConfig(accept_score=0.6)  # or MatchConfig().with_params(["accept_score=0.6"]), as --param reads it
for method in ("sem-str", "logic"):
    matcher = Matchmaker(loaded.kb, method, config)
    for name, requirements in sorted(loaded.requirements.items()):
        result = matcher.rank(requirements[0], explain=3)
        print(f"{name} by {method}: {result.status.value}")
        for candidate in result.candidates[:3]:
            pairs = ", ".join(f"{p.role} {p.shown_degree()} {p.similarity:.2f}" for p in candidate.pairs)
            verdict = "acceptable" if candidate.acceptable else "not acceptable"
            print(f"  {candidate.score:.3f} {candidate.label} ({verdict}): {pairs}")
report = evaluate_collection(folder, ["sem-str", "logic"], config, loaded=loaded)
print(report.text())
