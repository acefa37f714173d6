"""cbrs: a knowledge-base service that lets service robots find and use the services around them.

From Python, the library the ``cbrs`` command and ``cbrs serve`` are thin layers over:

- ``cbrs.kb``: ``KnowledgeBase.open(":memory:")`` (or a directory, or a server's URL), its ``load``,
  ``query``, ``select`` (the named queries), ``update`` and ``registry``; its errors, all
  ``KnowledgeBaseError``, keep what was wrong.
- ``cbrs.reasoner``: ``Matchmaker(kb, method).rank(requirement)``, Sem-Str and the baselines (``METHODS``).
- ``cbrs.actions``: ``Composer(kb).compose(task)`` for a plan or why there is none, ``run_task`` to run it.
- ``cbrs.sim`` (the ``[sim]`` extra): ``HomeWorld``, the simulated home a task runs in.

README.md's "The same knowledge base from Python" and docs/examples/lab19_notebook.py show them in use.
"""

__version__ = "0.1.0"
