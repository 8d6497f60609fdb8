"""RankByRelevance (ζ, ρ): rank the affordances by similarity to the current instruction."""

from __future__ import annotations

import py_trees

from scone_bt.behaviours.base import Keys, StageBehaviour

__all__ = ["RankByRelevance"]


class RankByRelevance(StageBehaviour):
    READS = (Keys.AFFORDANCES,)
    WRITES = (Keys.INSTRUCTION, Keys.RANKED, Keys.ACTION_EMBEDDINGS)

    def setup(self, **kwargs: object) -> None:
        self.embedder = self.services.embedder()

    def update(self) -> py_trees.common.Status:
        from scone_bt.relevance import rank_actions

        instruction = self.services.human.current_instruction
        affordances = self.read(Keys.AFFORDANCES, [])
        self.write(Keys.INSTRUCTION, instruction)
        if instruction is None:
            self.write(Keys.RANKED, [])
            self.write(Keys.ACTION_EMBEDDINGS, {})
            self.feedback_message = "recipe finished"
            return py_trees.common.Status.SUCCESS
        texts = [a.text for a in affordances]
        ranked = rank_actions(instruction, texts, self.embedder) if texts else []
        vectors = self.embedder.embed(texts) if texts else []
        self.write(Keys.RANKED, ranked)
        self.write(Keys.ACTION_EMBEDDINGS, dict(zip(texts, vectors, strict=True)))
        self.feedback_message = (
            f"best: {ranked[0].text} ({ranked[0].relevance:.2f})" if ranked else "nothing to rank"
        )
        return py_trees.common.Status.SUCCESS
