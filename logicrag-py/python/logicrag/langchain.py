"""Logic-RAG as a LangChain retriever, in process.

``LogicRagRetriever(source=src, k=4)`` is a langchain-core
``BaseRetriever``: for a question it asks every window of ``src`` (or one,
with ``window=``), and returns one ``Document`` per window — the windows
that answer yes first, then the others, in window order, at most ``k`` —
whose ``page_content`` is the retrieval context a multimodal model reads
(C2: the proved answer with its bindings and proofs, or why not; C3: the
window's facts in words) and whose ``metadata`` holds the window, its
frames, the answer, the query, the bindings and the probability that the
answer is right.

Install the extra: ``pip install "logicrag[langchain]"``.

>>> from logicrag.langchain import LogicRagRetriever
>>> r = LogicRagRetriever(source=logicrag.Engine().open("sim:urban_crossing"), k=2)
>>> docs = r.invoke("Is the pedestrian walking?")  # doctest: +SKIP
"""

from __future__ import annotations

from typing import Any, Literal

try:
    from langchain_core.callbacks import CallbackManagerForRetrieverRun
    from langchain_core.documents import Document
    from langchain_core.retrievers import BaseRetriever
except ImportError as e:  # pragma: no cover - depends on the environment
    raise ImportError(
        'logicrag.langchain needs langchain-core: pip install "logicrag[langchain]"'
    ) from e
from pydantic import ConfigDict, Field

from . import Source

__all__ = ["LogicRagRetriever"]


class LogicRagRetriever(BaseRetriever):
    """Retrieves proved answers: one Document per window, at most ``k``.

    ``source`` is an open ``logicrag.Source``; ``window`` restricts the
    retrieval to one window; ``context`` chooses what ``page_content``
    holds: ``"c2c3"`` (default, the paper's C3 condition: answer and
    facts), ``"c2"`` (the answer, its bindings and proofs, or why not).
    """

    model_config = ConfigDict(arbitrary_types_allowed=True)

    source: Source
    k: int = Field(default=4, ge=1)
    window: str | None = None
    context: Literal["c2", "c2c3"] = "c2c3"

    def _get_relevant_documents(
        self, query: str, *, run_manager: CallbackManagerForRetrieverRun
    ) -> list[Document]:
        asked = self.source.ask(query, window=self.window, proofs=False)
        results: list[dict[str, Any]] = asked["results"]
        # The windows that say yes first: those are the ones the answer
        # rests on; then the others, whose why-not or unknown still informs.
        ranked = [r for r in results if r["answer"] == "yes"] + [r for r in results if r["answer"] != "yes"]
        docs = []
        for r in ranked[: self.k]:
            ctx = self.source.context(query, r["window"])
            docs.append(
                Document(
                    id=f"{self.source.video}/{r['window']}",
                    page_content=_page(ctx, self.context),
                    metadata={
                        "video": self.source.video,
                        "window": r["window"],
                        "first_frame": r["first_frame"],
                        "last_frame": r["last_frame"],
                        "answer": r["answer"],
                        "query": r["query"],
                        "count": r["count"],
                        "bindings": [dict(b) for b in r["bindings"]],
                        # How sure the answer is (None for unknown/invalid).
                        "probability": r.get("probability"),
                    },
                )
            )
        return docs


def _page(ctx: dict[str, Any], which: str) -> str:
    """The context as the text a model reads (the layout of ``logicrag context``)."""
    lines = []
    if ctx.get("question"):
        lines.append(f"Question: {ctx['question']}")
    lines.append(f"Logical query: {ctx['query']}")
    lines.append("")
    lines.append("[C2] Inference result:")
    lines.extend(f"- {s}" for s in ctx["c2"])
    if which == "c2c3":
        lines.append("")
        lines.append("[C3] Scene facts:")
        lines.extend(f"- {s}" for s in ctx["c3"])
    return f"Window {ctx['window']}.\n" + "\n".join(lines) + "\n"
