"""What is computed and drawn from a recorded run: eq (19), IMO manoeuvres, reports, figures."""
