// env: the interface of anything that acts in a tracking environment (a
// learned policy, a scripted controller), so that evaluation and rendering
// need not know how it is implemented.
#ifndef MIMIC2D_ENV_POLICY_H_
#define MIMIC2D_ENV_POLICY_H_

namespace m2d {

class Policy {
 public:
  virtual ~Policy() = default;
  // Writes `batch` action rows for `batch` observation rows (raw, as the
  // environment writes them). Deterministic policies return the mean.
  virtual void Act(const float* observations, int batch, float* actions) = 0;
  virtual int observation_size() const = 0;
  virtual int action_size() const = 0;
};

}  // namespace m2d

#endif  // MIMIC2D_ENV_POLICY_H_
