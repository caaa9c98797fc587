// Pinocchio's own templated algorithms on CasADi's symbolic scalar (casadi::SX): what
// `pinocchio.casadi` (cpin) wraps for Python, built here because the PyPI `pin` wheels are
// compiled without CasADi support (pinocchio issues #2578, #2759).
//
// Usage: pin_casadi_mv MODEL.txt OUT.casadi
// MODEL.txt is a pinocchio::Model in Pinocchio's text serialization (Python:
// `model.saveToText(path)` on the model pin.buildModelFromXML built from the pruned URDF; the
// headers for Pinocchio's URDF parser are not in the wheels). The model is loaded, its gravity
// set to (0, 0, -9.81) in the root frame, cast to casadi::SX (ModelTpl<SX>, as cpin.Model(model)
// does), and a casadi::Function "pin_MV": (q, v) -> (M, V, T) written with Function::save:
// M = crba(q) with the upper triangle mirrored to the lower, V = computePotentialEnergy(q),
// T = computeKineticEnergy after forwardKinematics(q, v). Python loads it with
// casadi.Function.load. Build: build.sh.
#include <pinocchio/autodiff/casadi.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/serialization.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/energy.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <iostream>

int main(int argc, char ** argv)
{
  if (argc != 3)
  {
    std::cerr << "usage: pin_casadi_mv URDF OUT.casadi\n";
    return 2;
  }
  pinocchio::Model model;
  model.loadFromText(argv[1]);
  model.gravity.linear() << 0.0, 0.0, -9.81;
  model.gravity.angular().setZero();
  if (model.nq != model.nv)
  {
    std::cerr << "nq != nv: only 1-dof joints supported\n";
    return 1;
  }
  typedef casadi::SX ADScalar;
  typedef pinocchio::ModelTpl<ADScalar> ADModel;
  typedef ADModel::Data ADData;
  ADModel ad_model = model.cast<ADScalar>();
  ADData ad_data(ad_model);

  const int n = model.nv;
  casadi::SX cs_q = casadi::SX::sym("q", n);
  casadi::SX cs_v = casadi::SX::sym("v", n);
  ADModel::ConfigVectorType q_ad(n);
  ADModel::TangentVectorType v_ad(n);
  for (int i = 0; i < n; ++i)
  {
    q_ad[i] = cs_q(i);
    v_ad[i] = cs_v(i);
  }

  pinocchio::crba(ad_model, ad_data, q_ad);
  ad_data.M.triangularView<Eigen::StrictlyLower>() =
    ad_data.M.transpose().triangularView<Eigen::StrictlyLower>();
  casadi::SX M(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      M(i, j) = ad_data.M(i, j);

  ADScalar V = pinocchio::computePotentialEnergy(ad_model, ad_data, q_ad);
  pinocchio::forwardKinematics(ad_model, ad_data, q_ad, v_ad);
  ADScalar T = pinocchio::computeKineticEnergy(ad_model, ad_data);

  casadi::Function f("pin_MV", {cs_q, cs_v}, {M, V, T}, {"q", "v"}, {"M", "V", "T"});
  f.save(argv[2]);
  std::cout << "nq " << model.nq << " joints";
  for (int i = 1; i < model.njoints; ++i)
    std::cout << " " << model.names[i];
  std::cout << "\n";
  return 0;
}
