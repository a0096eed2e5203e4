"""The language: text -> syntax tree -> IR -> timeline of episodes, the C-V model, the
descriptor table and lint. All that ``aouc lint`` needs; no numpy."""
