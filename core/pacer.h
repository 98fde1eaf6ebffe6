#pragma once
// Pacing of presents (tile windows, previews, the control window): at most one per interval (a
// display refresh); a change that came too soon stays pending and is shown by a later due().
// Pure; times in seconds on any clock the caller keeps.
namespace isowall {

class PresentPacer {
  public:
    explicit PresentPacer(double interval_s) : interval_s_(interval_s) {}
    // Something changed at `now`: true when it may be shown now (it then counts as shown).
    bool changed(double now) {
        pending_ = true;
        return due(now);
    }
    // Whether a pending change is due at `now` (it then counts as shown).
    bool due(double now) {
        if (!pending_ || now - last_s_ < interval_s_) return false;
        shown(now);
        return true;
    }
    bool pending() const { return pending_; }
    // Seconds from `now` until a pending change is due (0 when it is; meaningless without one).
    double wait_s(double now) const {
        const double left = last_s_ + interval_s_ - now;
        return left > 0 ? left : 0;
    }
    void shown(double now) {
        pending_ = false;
        last_s_ = now;
    }
    double interval_s() const { return interval_s_; }

  private:
    double interval_s_;
    double last_s_ = -1e300;
    bool pending_ = false;
};

}  // namespace isowall
