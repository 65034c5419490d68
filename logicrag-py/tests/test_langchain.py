"""logicrag.langchain.LogicRagRetriever: a langchain-core BaseRetriever in
process, whose Documents are the C2/C3 context of the windows asked."""

from __future__ import annotations

import pytest

import logicrag

pytest.importorskip("langchain_core", reason="needs langchain-core (pip install 'logicrag[langchain]')")
from langchain_core.documents import Document  # noqa: E402
from langchain_core.retrievers import BaseRetriever  # noqa: E402

from logicrag.langchain import LogicRagRetriever  # noqa: E402


@pytest.fixture(scope="module")
def src():
    return logicrag.Engine().open("sim:urban_crossing")


def test_invoke_returns_the_yes_windows_first_with_their_context(src):
    r = LogicRagRetriever(source=src, k=4)
    assert isinstance(r, BaseRetriever)
    q = "Is the pedestrian walking?"
    docs = r.invoke(q)
    asked = src.ask(q)["results"]
    yes = [x["window"] for x in asked if x["answer"] == "yes"]
    no = [x["window"] for x in asked if x["answer"] != "yes"]
    assert [d.metadata["window"] for d in docs] == (yes + no)[:4]
    for d in docs:
        assert isinstance(d, Document)
        ctx = src.context(q, d.metadata["window"])
        assert d.id == f"{src.video}/{d.metadata['window']}"
        assert d.page_content.startswith(f"Window {d.metadata['window']}.\nQuestion: {q}\n")
        for line in ctx["c2"] + ctx["c3"]:
            assert f"- {line}\n" in d.page_content
        result = next(x for x in asked if x["window"] == d.metadata["window"])
        assert d.metadata["answer"] == result["answer"]
        assert d.metadata["query"] == result["query"]
        assert d.metadata["bindings"] == [dict(b) for b in result["bindings"]]
        assert d.metadata["probability"] == result.get("probability")
        if d.metadata["answer"] == "yes":
            assert d.metadata["bindings"] and all("x" in b for b in d.metadata["bindings"])


def test_k_bounds_the_documents_and_window_restricts_them(src):
    assert len(LogicRagRetriever(source=src, k=1).invoke("Are there stopped vehicles?")) == 1
    w = src.windows[2]
    docs = LogicRagRetriever(source=src, k=4, window=w).invoke("Are there stopped vehicles?")
    assert [d.metadata["window"] for d in docs] == [w]
    c2 = LogicRagRetriever(source=src, k=1, context="c2").invoke("Are there stopped vehicles?")[0]
    assert "[C2]" in c2.page_content and "[C3]" not in c2.page_content
    with pytest.raises(ValueError):
        LogicRagRetriever(source=src, k=0)


def test_batch_answers_each_question(src):
    r = LogicRagRetriever(source=src, k=2)
    qs = ["Is the pedestrian walking?", "Is there a truck?", "Vehicles(x) ^ Moving(x)"]
    out = r.batch(qs)
    assert len(out) == 3
    for q, docs in zip(qs, out):
        assert docs == r.invoke(q)
    # No truck in this scene: every window says no, with why-not in C2.
    assert all(d.metadata["answer"] == "no" for d in out[1])


def test_an_unreadable_question_raises_and_an_invalid_query_says_why(src):
    # The grammar cannot read it: the CLI's error, as ValueError.
    with pytest.raises(ValueError, match="saunter"):
        LogicRagRetriever(source=src).invoke("Is someone sauntering?")
    # A query that does not fit the LogicPad is answered "invalid", with the
    # diagnostic in C2, as `logicrag ask` answers it.
    docs = LogicRagRetriever(source=src, k=1).invoke("Levitates(x)")
    assert docs[0].metadata["answer"] == "invalid"
    assert "Levitates" in docs[0].page_content
