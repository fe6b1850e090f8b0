"""Stable anchors for the numbered sections of the theory note, and links to them.

The code cites the theory note as "docs/theory.md §N" (tests/test_citations.py checks that
every cited N exists). This extension

- gives the heading "## N. …" of docs/theory.md the anchor ``sec-N`` (theory.html#sec-N),
  which stays put when a heading's words change or sections are added after it, and
  registers it as the label ``theory-sec-N`` (``:ref:`theory-sec-N```);
- turns every citation in a docstring rendered by autodoc — "docs/theory.md §N", and the
  further "§M" of a group such as "docs/theory.md §14 and §15" — into a link to that anchor
  (a citation of a section that does not exist is an undefined label, a build warning);
- does the same in the running text of the reST pages and of the gallery's pages (the
  examples' docstrings);
- links the bare "§N" of the theory note's own text to its section.
"""

from __future__ import annotations

import re

from docutils import nodes

THEORY = "theory"  # the docname of docs/theory.md
HEADING = re.compile(r"^(\d+)\.\s")
GROUP = re.compile(r"docs/theory\.md\s+§\d+(?:\s*(?:,|–|and)\s*§\d+)*")
SECTION = re.compile(r"§(\d+)")


def anchor(number: int | str) -> str:
    """The HTML id of section ``number`` of the theory page."""
    return f"sec-{number}"


def label(number: int | str) -> str:
    """The Sphinx label of section ``number`` of the theory page."""
    return f"theory-sec-{number}"


def numbered_sections(doctree: nodes.document) -> dict[int, nodes.section]:
    """The sections "N. …" directly below the page's title, by N."""
    found = {}
    for section in doctree.findall(nodes.section):
        parent = section.parent
        if not (isinstance(parent, nodes.section) and isinstance(parent.parent,
                                                                  nodes.document)):
            continue
        if m := HEADING.match(section[0].astext()):
            found[int(m[1])] = section
    return found


def add_anchors(app, doctree: nodes.document) -> None:
    """``doctree-read``: anchor and label every numbered section of the theory note, and
    link its bare "§N" to them."""
    env = app.env
    current = getattr(env, "current_document", None)  # Sphinx 8.2 and later
    docname = current.docname if current is not None else env.docname
    if docname != THEORY:
        return
    std = env.get_domain("std")
    sections = numbered_sections(doctree)
    for number, section in sections.items():
        ident = anchor(number)
        section["ids"].insert(0, ident)  # the first id is the heading's permalink
        doctree.ids[ident] = section
        std.anonlabels[label(number)] = docname, ident
        std.labels[label(number)] = docname, ident, section[0].astext()
    _link_bare_citations(doctree, set(sections))


def _link_bare_citations(doctree: nodes.document, numbers: set[int]) -> None:
    """Every "§N" of running text (not in a formula, code or a heading) becomes a link to
    section N of the same page."""
    skip = (nodes.literal, nodes.literal_block, nodes.math, nodes.math_block, nodes.title,
            nodes.reference, nodes.raw)
    for text in list(doctree.findall(nodes.Text)):
        if any(isinstance(p, skip) for p in _ancestors(text)) or "§" not in text:
            continue
        pieces: list[nodes.Node] = []
        last = 0
        for m in SECTION.finditer(text):
            if int(m[1]) not in numbers:
                continue
            pieces.append(nodes.Text(text[last:m.start()]))
            pieces.append(nodes.reference(m[0], m[0], internal=True, refid=anchor(m[1])))
            last = m.end()
        if pieces:
            pieces.append(nodes.Text(text[last:]))
            text.parent.replace(text, [p for p in pieces if p.astext()])


def _ancestors(node: nodes.Node):
    while node.parent is not None:
        node = node.parent
        yield node


def link_citations(text: str) -> str:
    """reST of ``text`` with every theory-note citation a ``:ref:`` to its section."""
    return GROUP.sub(lambda m: _group(m[0]), text)


def _group(citation: str) -> str:
    """"docs/theory.md §14 and §15" → the first with its path as one link, then each §M."""
    first = SECTION.search(citation)
    assert first is not None
    head = f":ref:`{citation[:first.end()]} <{label(first[1])}>`"
    rest = SECTION.sub(lambda s: f":ref:`§{s[1]} <{label(s[1])}>`", citation[first.end():])
    return head + rest


def process_docstring(app, what, name, obj, options, lines: list[str]) -> None:
    """``autodoc-process-docstring``: link the citations, keeping the number of lines."""
    if not any("docs/theory.md" in line for line in lines):
        return
    linked = link_citations("\n".join(lines)).split("\n")
    assert len(linked) == len(lines)
    lines[:] = linked


def process_page_source(app, docname: str, source: list[str]) -> None:
    """``source-read``: link the citations of the reST pages, the gallery's included (the
    examples' docstrings), in their running text, not in their code (indented lines)."""
    if docname == THEORY:
        return
    chunks = re.split(r"((?:^[ \t].*\n?|^\n)+)", source[0], flags=re.M)
    source[0] = "".join(chunk if i % 2 else link_citations(chunk)
                        for i, chunk in enumerate(chunks))


def setup(app):
    app.connect("doctree-read", add_anchors)
    app.connect("source-read", process_page_source)
    # after numpydoc (500), which writes the docstrings of properties into Attributes
    app.connect("autodoc-process-docstring", process_docstring, priority=600)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
