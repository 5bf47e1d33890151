"""ament_pep257 with ament's own convention over the repository (the ament_python template's test)."""
import pytest

from lint_scope import excluded_paths, REPO

main = pytest.importorskip('ament_pep257.main').main


@pytest.mark.linter
@pytest.mark.pep257
def test_pep257(monkeypatch):
    monkeypatch.chdir(REPO)
    rc = main(argv=['.', '--exclude', *excluded_paths()])
    assert rc == 0, 'Found code style errors / warnings'
