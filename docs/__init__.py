"""jik's documentation folder. The wheel ships one page of it, the paper's errata: where the
printed paper and jik disagree, each with the command that shows it (``jik errata``, and
``GET /errata`` of ``jik serve``). The other pages are read in the repository and the API
reference is built by mkdocs (mkdocs.yml)."""

from importlib.resources import files

#: The page of the paper's errata.
ERRATA = "paper-errata.md"


def paper_errata() -> str:
    """The text of ``docs/paper-errata.md`` (Markdown), from the tree or the installed wheel."""
    return files(__name__).joinpath(ERRATA).read_text(encoding="utf-8")
