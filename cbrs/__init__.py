"""cbrs: a knowledge-base service that lets service robots find and use the services around them."""

__version__ = "0.1.0"
