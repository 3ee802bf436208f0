"""griffe extension for the API reference: the docstrings' Sphinx roles become links.

jik's docstrings cite other objects as Sphinx does (``:func:`solve_batch```,
``:data:`~jik.engine.validation.MAX_COORDINATE```); mkdocstrings reads docstrings as Markdown,
where a role shows as the text ":func:" before the name. Before they are rendered, each role
becomes an optional cross-reference of mkdocs-autorefs to the object it names, found from the
scope of the docstring's object as Python would find the name there: a link where the
reference documents that object, else its name as code. ``~`` shows the last component only,
as in Sphinx. mkdocs.yml loads this with the Python handler's ``extensions``.
"""

from __future__ import annotations

import re
from typing import Any

from griffe import AliasResolutionError, Extension, NameResolutionError, Object

#: A role: ``~`` or not, then the name (which a docstring may break across lines after a dot),
#: or a title and the name in angle brackets.
ROLE = re.compile(r":(?:func|class|data|mod|meth|attr|exc|obj):`(~?)([^`<]+?)(?:\s*<([^`>]+)>)?`")


def _find(obj: Object, path: str) -> str | None:
    """The canonical path of the object at ``path`` in ``obj``'s collection, or None."""
    try:
        found = obj.modules_collection[path]
        return found.canonical_path if not found.is_alias else found.final_target.path
    except (KeyError, ValueError, AliasResolutionError):
        return None


def _resolve(obj: Object, target: str) -> str | None:
    """The path of the object that ``target`` names in the scope of ``obj`` (its name resolved
    there, else absolute, else relative to one of the packages around it)."""
    head, _, rest = target.partition(".")
    try:
        start = obj.resolve(head)
    except NameResolutionError:
        start = None
    if start is not None and (found := _find(obj, f"{start}.{rest}" if rest else start)):
        return found
    if found := _find(obj, target):
        return found
    scope = obj.module
    while scope is not None:
        if found := _find(obj, f"{scope.path}.{target}"):
            return found
        scope = scope.parent
    return None


def _reference(obj: Object, match: re.Match) -> str:
    tilde, text, named = match.groups()
    target = re.sub(r"\s+", "", named or text).lstrip(".")
    shown = text.strip() if named else target.rsplit(".", 1)[-1] if tilde else target
    shown = f"<code>{shown}</code>"
    path = _resolve(obj, target)
    return f'<autoref identifier="{path}" optional>{shown}</autoref>' if path else shown


def _objects(obj: Object):
    yield obj
    for member in obj.members.values():
        if not member.is_alias:
            yield from _objects(member)  # type: ignore[arg-type]


class SphinxRoles(Extension):
    """Rewrites the roles of every docstring of a package once it is loaded."""

    def on_package(self, *, pkg: Any, **kwargs: Any) -> None:
        for obj in _objects(pkg):
            if obj.docstring is not None and ":" in obj.docstring.value:
                obj.docstring.value = ROLE.sub(
                    lambda m, o=obj: _reference(o, m), obj.docstring.value
                )
