"""ament_flake8 with ament's own configuration over the repository (the ament_python template's test)."""
import pytest

from lint_scope import excluded_paths, REPO

main_with_errors = pytest.importorskip('ament_flake8.main').main_with_errors


@pytest.mark.flake8
@pytest.mark.linter
def test_flake8(monkeypatch):
    monkeypatch.chdir(REPO)
    rc, errors = main_with_errors(argv=['--exclude', *excluded_paths()])
    assert rc == 0, \
        'Found %d code style errors / warnings:\n' % len(errors) + \
        '\n'.join(errors)
