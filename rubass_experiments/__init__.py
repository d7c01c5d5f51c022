"""The paper's experiments, apart from the product: simulated robots (kinematics, faults, the
Kobuki-like and Frobit-like bases, a go-to-goal driver, a world with an obstacle), the fault
injector, the private rosmaster and process supervision, and the runner behind
`rubass experiments`. The monitor never imports this package."""
