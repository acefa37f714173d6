"""Benchmark: the knowledge browser's pages on a store, in this process (Flask's test client, no socket).

Run: python bench/web_pages.py STORE [--repeat N]. STORE is a store directory, e.g. one made with
``cbrs --store /tmp/tc4 load --catalog owls-tc4/ontology owls-tc4/services``, or :memory: for the
bundled data. Each page is asked once cold (first request after the app starts) and then N times; the
figures are the cold time, the median of the rest, and the page's size. To compare two versions, run
each with its own tree first on PYTHONPATH, alternating, in one shell session.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app

# The pages a user opens first on a store, by what they read: OWLS-TC IRIs where the store has them.
OWLS_TC = "http://127.0.0.1/ontology/"
PAGES = {
    "overview": "/",
    "taxonomy": "/taxonomy",
    "taxonomy search": "/taxonomy?q=car",
    "services": "/services",
    "class (bundled)": "/taxonomy/class?iri=home:RobotPosition",
    "class (OWLS-TC)": f"/taxonomy/class?iri={OWLS_TC}my_ontology.owl%23Car",
    "class Price (OWLS-TC)": f"/taxonomy/class?iri={OWLS_TC}concept.owl%23Price",
    "service (bundled)": "/service?iri=svc:LocateMobileRobot_CeilingCamera01",
    "search": "/search?q=price",
    "resource owl:Class": "/resource?iri=owl:Class",
    "plan (bundled)": "/plans?task=FetchMyPen",
    # the SPARQL editor on the whole store: it shows 1,000 rows (docs/web.md, "A big store")
    "editor SELECT *": "/query?query=SELECT%20*%20WHERE%20%7B%20%3Fs%20%3Fp%20%3Fo%20%7D",
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("store")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--only", default="", help="time only the pages whose name contains this")
    args = parser.parse_args()
    kb = KnowledgeBase.open(args.store)
    client = create_app(SparqlService(kb)).test_client()
    print(f"# {platform.python_version()} on {os.cpu_count()} cores; load average {os.getloadavg()}")
    print(f"# store {args.store}; {args.repeat} warm requests a page; times in ms")
    print(f"{'page':24} {'status':>6} {'cold':>8} {'warm':>8} {'bytes':>10}")
    for name, path in PAGES.items():
        if args.only not in name:
            continue
        start = time.perf_counter()
        first = client.get(path)
        cold = (time.perf_counter() - start) * 1000
        warm = []
        for _ in range(args.repeat):
            start = time.perf_counter()
            client.get(path).close()
            warm.append((time.perf_counter() - start) * 1000)
        print(f"{name:24} {first.status_code:>6} {cold:8.0f} {statistics.median(warm):8.0f} {len(first.data):>10}")
        first.close()
    kb.close()


if __name__ == "__main__":
    main()
