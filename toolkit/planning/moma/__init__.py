"""MoMa-LLM: structured scene text, command grounding, the planner loop."""
