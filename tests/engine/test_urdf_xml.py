"""URDF text is parsed with hardened XML settings: no DTD, no entities, no network, UTF-8 only."""

import pytest

from jik.engine.exceptions import InvalidInputError
from jik.engine.urdf import UrdfChain, parse_urdf
from tests.engine.test_urdf import TEXT

pytest.importorskip("yourdfpy")

SECRET = "s3cr3t-entity-text"
BODY = TEXT.split("?>", 1)[1]


#: UTF-7's base64 runs for the characters of a DTD (each its UTF-16 code in modified base64).
UTF7 = {"<": "+ADw-", ">": "+AD4-", "!": "+ACE-", "[": "+AFs-", "]": "+AF0-"}


def _utf7(s: str) -> str:
    """``s`` as UTF-7 text with '<', '>', '!', '[' and ']' written as base64 runs."""
    return "".join(UTF7.get(c, c) for c in s)


def _entity_urdf(encoding: str) -> str:
    """A URDF whose link name is an internal entity, its DOCTYPE written in ``encoding``."""
    doctype = f'<!DOCTYPE robot [<!ENTITY x "{SECRET}">]>'
    body = BODY.replace('<link name="tool"/>', '<link name="tool"/><link name="&x;"/>')
    prologue = f'<?xml version="1.0" encoding="{encoding}"?>'
    return prologue + (_utf7(doctype) + body if encoding == "UTF-7" else doctype + body)


def test_a_doctype_hidden_by_utf7_is_refused_and_never_expanded():
    """The UTF-7 text has no literal '<!DOCTYPE': the declared encoding itself is refused, and
    the entity's text appears in no message."""
    text = _entity_urdf("UTF-7")
    assert "<!DOCTYPE" not in text and "+ADw-" in text
    assert text.encode().decode("utf-7").count("<!DOCTYPE") == 1
    with pytest.raises(InvalidInputError) as err:
        UrdfChain(text, "nowhere")
    assert err.value.field == "urdf"
    assert "encoding" in str(err.value) and "UTF-7" in str(err.value)
    assert SECRET not in str(err.value)


@pytest.mark.parametrize("encoding", ["UTF-16", "ISO-8859-1", "EBCDIC-US", "utf-32"])
def test_other_declared_encodings_are_refused(encoding):
    text = f'<?xml version="1.0" encoding="{encoding}"?>' + BODY
    with pytest.raises(InvalidInputError, match="encoding"):
        parse_urdf(text)


@pytest.mark.parametrize("encoding", ["UTF-8", "utf-8", "US-ASCII", "ascii"])
def test_utf8_and_ascii_declarations_are_accepted(encoding):
    text = f"<?xml version='1.0' encoding='{encoding}'?>" + BODY
    assert UrdfChain(text, "tool").p == 4


@pytest.mark.parametrize(
    "prefix",
    [
        '<!DOCTYPE robot [<!ENTITY x "a">]>',
        '<!DOCTYPE robot SYSTEM "http://example.invalid/robot.dtd">',
        '<!doctype robot [<!ENTITY x SYSTEM "file:///etc/hostname">]>',
    ],
)
def test_any_dtd_is_refused(prefix):
    with pytest.raises(InvalidInputError, match=r"DTD|DOCTYPE") as err:
        parse_urdf('<?xml version="1.0"?>' + prefix + BODY)
    assert err.value.field == "urdf"


def test_an_undeclared_entity_is_refused_not_expanded():
    text = TEXT.replace('<link name="tool"/>', '<link name="tool"/><link name="&x;"/>')
    with pytest.raises(InvalidInputError, match="not a valid URDF"):
        parse_urdf(text)


def test_the_parser_itself_refuses_a_dtd_past_the_text_check():
    """The hardened parse stands alone: a DTD that reached it is refused, its entity unread."""
    from jik.engine.urdf_parse import _hardened_parse

    with pytest.raises(InvalidInputError, match="DTD") as err:
        _hardened_parse(f'<!DOCTYPE r [<!ENTITY x "{SECRET}">]><r>&x;</r>'.encode(), "urdf")
    assert SECRET not in str(err.value)


@pytest.mark.parametrize("reference", ["&#10;", "&#13;", "&#x2028;", "&#9;", "&#133;"])
@pytest.mark.parametrize("kind", ["joint", "link"])
def test_a_name_holding_a_line_break_or_control_character_is_refused(reference, kind):
    """A character reference (no entity) put a line break in a joint's name, which the
    verdicts print: a dashboard export's '#' header line broke and the text after it became a
    CSV row of its own ('pseudoinverse,1,1,=HYPERLINK(1)')."""
    old = 'name="shoulder"' if kind == "joint" else 'name="forearm"'
    name = old[:-1] + reference + 'pseudoinverse,1,1,=HYPERLINK(1)"'
    text = TEXT.replace(old, name).replace('link="forearm"', name.replace("name", "link"))
    with pytest.raises(InvalidInputError, match=f"a {kind}'s name must be one line") as err:
        UrdfChain(text, "tool")
    assert err.value.field == "urdf"
