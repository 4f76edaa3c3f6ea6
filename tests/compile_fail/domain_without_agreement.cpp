// Must not compile: a domain part without agree() (domain/domain.hpp).
#include <sphshell/domain/domain.hpp>

#include <string>

struct DomainWithoutAgreement {
  static constexpr bool is_distributed = false;
  int rank() const { return 0; }
  int size() const { return 1; }
  bool is_root() const { return true; }
  template <class Body>
  void collectively(Body&& body) const {
    body();
  }
  bool first_process_decides(bool value) const { return value; }
  std::string checkpoint_file(const std::string& path) const { return path; }
};

int main() { return sphshell::domain::check_domain<DomainWithoutAgreement>() ? 0 : 1; }
