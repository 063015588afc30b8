"""`gesturecast --help` opens with one plain line saying what the product does."""

from gesturecast.cli import build_parser


def test_help_opens_with_one_line_about_the_product():
    description = build_parser().description
    assert "\n" not in description and "``" not in description and "register" not in description
    assert description.startswith("Real-time avatar driver: speech")
