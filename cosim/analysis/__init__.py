"""What is computed and drawn from a recorded run: eq (19), the MSC.137(76) manoeuvres and
criteria, reports, figures, plates and animations."""
