"""Chat models over OpenAI-compatible endpoints: client, exchange records, transcripts, replay."""
